#include "cli/accuracy_plots.hpp"

#include <batchcol/errors.hpp>

#include <cerrno>
#include <filesystem>
#include <iostream>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace batchcol::cli {
namespace {

const char* const kInstallCommand = "apt-get install -y python3-matplotlib";

bool has_matplotlib(const std::string& python) {
  return run_program({python, "-c", "import matplotlib"}, true) == 0;
}

}  // namespace

std::string default_plot_script() {
#ifdef BATCHCOL_PLOT_SCRIPT
  return BATCHCOL_PLOT_SCRIPT;
#else
  return "tools/plot_accuracy.py";
#endif
}

int run_program(const std::vector<std::string>& argv, bool quiet, const std::vector<std::string>& extra_env) {
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  std::vector<std::string> env_storage(extra_env);
  std::vector<char*> env;
  for (char** e = environ; e && *e; ++e) env.push_back(*e);
  for (std::string& e : env_storage) env.push_back(e.data());
  env.push_back(nullptr);

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  if (quiet) {
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
  } else {
    posix_spawn_file_actions_adddup2(&actions, STDERR_FILENO, STDOUT_FILENO);
  }
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, args[0], &actions, nullptr, args.data(), env.data());
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) return -1;
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) return -1;
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

bool prepare_plotting(const PlotSettings& s) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(s.script, ec)) {
    throw InputError("--plot-script " + s.script + ": plot script not found (pass its path, or --no-plots)");
  }
  if (has_matplotlib(s.python)) return true;
  if (s.install && ::geteuid() == 0) {
    std::cerr << "batchcol: " << s.python << " has no matplotlib: running " << kInstallCommand << "\n";
    const std::vector<std::string> noninteractive = {"DEBIAN_FRONTEND=noninteractive"};
    if (run_program({"/usr/bin/apt-get", "install", "-y", "python3-matplotlib"}, false, noninteractive) != 0) {
      // A fresh machine may have no package lists yet.
      run_program({"/usr/bin/apt-get", "update"}, false, noninteractive);
      run_program({"/usr/bin/apt-get", "install", "-y", "python3-matplotlib"}, false, noninteractive);
    }
    if (has_matplotlib(s.python)) return true;
  }
  std::cerr << "batchcol: warning: no plots: " << s.python << " cannot import matplotlib; install it with\n"
            << "  sudo " << kInstallCommand << "\n"
            << "then rerun, or plot the CSV with: " << s.python << " " << s.script << " DIR/accuracy.csv DIR\n";
  return false;
}

void run_plot_script(const PlotSettings& s, const std::string& csv, const std::string& out_dir) {
  const int code = run_program({s.python, s.script, csv, out_dir}, false);
  if (code != 0) {
    throw InputError("plot script " + s.script + " failed (exit code " + std::to_string(code) + "); " + csv +
                     " is complete, plots may be missing");
  }
}

}  // namespace batchcol::cli
