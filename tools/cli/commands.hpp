// Subcommands of the batchcol CLI. Each add_*_command registers its options on `parent` and returns the
// subcommand with a runner to call when that subcommand was parsed.
#pragma once

#include <CLI/CLI.hpp>
#include <batchcol/derivatives.hpp>

#include <functional>

namespace batchcol::cli {

struct Command {
  CLI::App* app = nullptr;
  std::function<int()> run;  // returns the exit code; throws InputError / std::exception on failure
};

Command add_demo_command(CLI::App& parent);
Command add_query_command(CLI::App& parent);
Command add_bench_command(CLI::App& parent);
Command add_stress_command(CLI::App& parent);
Command add_accuracy_command(CLI::App& parent);
Command add_descent_command(CLI::App& parent);

/// The derivative method named `name` (query and bench --derivatives); InputError naming --derivatives otherwise.
DerivativeMethod parse_derivative_method(const std::string& name);

Command add_rays_command(CLI::App& parent);

}  // namespace batchcol::cli
