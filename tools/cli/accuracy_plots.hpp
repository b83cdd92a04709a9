// The plotting step of `batchcol accuracy`: tools/plot_accuracy.py run by Debian's python (/usr/bin/python3) with
// python3-matplotlib, which is installed with apt-get when missing and running as root. Without root the command
// prints the install command, keeps the CSV and summary, and exits 0 with a warning.
#pragma once

#include <string>
#include <vector>

namespace batchcol::cli {

struct PlotSettings {
  std::string python = "/usr/bin/python3";  // not the `python3` on PATH, which may lack matplotlib
  std::string script;                        // tools/plot_accuracy.py
  bool install = true;                       // may run apt-get as root
};

/// The plot script of the source tree this binary was built from.
std::string default_plot_script();

/// Checked before the sweep so that a long run does not end without plots: throws InputError when the script is
/// missing; returns false (after printing a warning on stderr) when matplotlib is missing and cannot be installed.
bool prepare_plotting(const PlotSettings& settings);

/// Runs the script on `csv`, writing the figures into `out_dir`; throws InputError when it fails.
void run_plot_script(const PlotSettings& settings, const std::string& csv, const std::string& out_dir);

/// Runs a program (argv[0] is its path, no shell) and returns its exit code, or -1 when it could not start.
/// `quiet` discards its output; otherwise its stdout goes to our stderr (stdout stays the command's own).
int run_program(const std::vector<std::string>& argv, bool quiet, const std::vector<std::string>& extra_env = {});

}  // namespace batchcol::cli
