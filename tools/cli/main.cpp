// batchcol command-line tool. Exit codes: 0 success, 2 any error (bad flags, bad input, failed output).
#include "cli/commands.hpp"

#include <batchcol/errors.hpp>

#include "printable.hpp"

#include <algorithm>
#include <exception>
#include <new>
#include <iostream>
#include <string>
#include <vector>

namespace {

// One line, whatever the message quotes (the parts quoting untrusted text already escape and shorten it; this is
// the last guard): control characters escaped, at most 2000 bytes.
int fail(const char* message) {
  std::cerr << "batchcol: error: " << batchcol::detail::printable(message, 2000) << '\n';
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    CLI::App app{"batchcol: batched convex collision queries"};
    app.require_subcommand(1);
    const std::vector<batchcol::cli::Command> commands = {batchcol::cli::add_demo_command(app),
                                                          batchcol::cli::add_query_command(app),
                                                          batchcol::cli::add_bench_command(app),
                                                          batchcol::cli::add_accuracy_command(app),
                                                          batchcol::cli::add_stress_command(app),
                                                          batchcol::cli::add_descent_command(app),
                                                          batchcol::cli::add_rays_command(app)};
    // CLI11 would only say "A subcommand is required" for a misspelt one.
    const auto named = [&](const batchcol::cli::Command& c) { return c.app->check_name(argv[1]); };
    if (argc > 1 && argv[1][0] != '-' && std::none_of(commands.begin(), commands.end(), named)) {
      return fail((std::string("unknown subcommand '") + batchcol::detail::printable(argv[1], 64) + "' (valid: demo, query, bench, accuracy, stress, descent, rays)").c_str());
    }
    try {
      app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
      if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(e);  // --help
      return fail(e.what());
    }
    for (const auto& command : commands) {
      if (command.app->parsed()) return command.run();
    }
    return fail("no subcommand given");
  } catch (const batchcol::InputError& e) {
    return fail(e.what());
  } catch (const std::bad_alloc&) {
    return fail("out of memory: the input needs more memory than this machine can give (see \"Input limits\" in "
                "the README for the sizes batchcol accepts)");
  } catch (const std::exception& e) {
    return fail(e.what());
  } catch (...) {
    return fail("unknown failure");
  }
}
