#include "cli/accuracy_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <ostream>
#include <utility>

namespace batchcol::cli {
namespace {

std::string format(const char* spec, double v) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  if (std::isnan(v)) return "nan";
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, spec, v);
  return buffer;
}

std::string error_text(double v) { return format("%.4e", v); }

std::string speed_text(double pairs_per_second) {
  if (pairs_per_second >= 1e6) return format("%.2f M/s", pairs_per_second / 1e6);
  return format("%.0f k/s", pairs_per_second / 1e3);
}

std::string config_text(const AccuracyRow& r) {
  return std::string(to_string(r.point.solver)) + " " + (r.point.precision == Precision::float32 ? "float" : "double") +
         " tol " + format("%g", r.point.tolerance);
}

const char* precision_name(Precision p) { return p == Precision::float32 ? "float" : "double"; }

// Rows grouped by (case, regime) in the order they were measured.
std::vector<std::vector<const AccuracyRow*>> group_by_case(const std::vector<AccuracyRow>& rows) {
  std::vector<std::vector<const AccuracyRow*>> groups;
  for (const AccuracyRow& r : rows) {
    if (groups.empty() || groups.back().front()->case_name != r.case_name || groups.back().front()->regime != r.regime) {
      groups.emplace_back();
    }
    groups.back().push_back(&r);
  }
  return groups;
}

// Where there is no closed form, the reference is the gjk double run at tolerance 1e-12: that row scores 0 against
// itself by construction and must not count as evidence of accuracy.
bool is_the_reference(const AccuracyRow& r) {
  return r.reference != "analytic" && r.point.solver == Solver::gjk && r.point.precision == Precision::float64 &&
         r.point.tolerance == reference_options(1).tolerance;
}

bool usable(const AccuracyRow& r) { return r.non_finite == 0 && r.scored > 0 && !is_the_reference(r); }

// The row minimising `key` among those passing `keep`; null when none.
template <class Keep, class Key>
const AccuracyRow* best(const std::vector<const AccuracyRow*>& group, Keep keep, Key key) {
  const AccuracyRow* out = nullptr;
  for (const AccuracyRow* r : group) {
    if (keep(*r) && (!out || key(*r) < key(*out))) out = r;
  }
  return out;
}

void write_done_when(const std::vector<std::vector<const AccuracyRow*>>& groups, std::ostream& out) {
  out << "## Issue #5 \"done when\": double error <= 1e-9 m and float relative error <= 1e-5\n\n"
      << "Per case and regime: the most accurate double configuration (max |distance error| over the pairs) and the "
         "most accurate float configuration (max relative error).\n\n"
      << "| case | regime | best double: max error | configuration | best float: max relative error | configuration "
         "| double <= 1e-9 | float <= 1e-5 |\n|---|---|---|---|---|---|---|---|\n";
  std::size_t met = 0;
  for (const auto& g : groups) {
    const auto is = [](Precision p) { return [p](const AccuracyRow& r) { return usable(r) && r.point.precision == p; }; };
    const AccuracyRow* d = best(g, is(Precision::float64), [](const AccuracyRow& r) { return r.distance.max; });
    const AccuracyRow* f = best(g, is(Precision::float32), [](const AccuracyRow& r) { return r.distance_relative_max; });
    const bool d_ok = d && d->distance.max <= kDoubleTarget;
    const bool f_ok = f && f->distance_relative_max <= kFloatRelativeTarget;
    met += d_ok && f_ok ? 1 : 0;
    out << "| " << g.front()->case_name << " | " << to_string(g.front()->regime) << " | "
        << (d ? error_text(d->distance.max) : "-") << " | " << (d ? config_text(*d) : "-") << " | "
        << (f ? error_text(f->distance_relative_max) : "-") << " | " << (f ? config_text(*f) : "-") << " | "
        << (d_ok ? "yes" : "**no**") << " | " << (f_ok ? "yes" : "**no**") << " |\n";
  }
  out << "\n" << met << " of " << groups.size() << " case/regime combinations meet both thresholds.\n\n";
}

void write_cheapest(const std::vector<std::vector<const AccuracyRow*>>& groups, std::ostream& out) {
  out << "## Cheapest configuration per error level\n\n"
      << "The fastest configuration (pairs/s) whose max |distance error| over the pairs is within the level; "
         "\"-\" when none is.\n\n| case | regime |";
  for (double level : kSummaryLevels) out << " <= " << format("%g", level) << " m |";
  out << "\n|---|---|";
  for (std::size_t i = 0; i < std::size(kSummaryLevels); ++i) out << "---|";
  out << "\n";
  for (const auto& g : groups) {
    out << "| " << g.front()->case_name << " | " << to_string(g.front()->regime) << " |";
    for (double level : kSummaryLevels) {
      const AccuracyRow* r = best(
          g, [level](const AccuracyRow& x) { return usable(x) && x.distance.max <= level; },
          [](const AccuracyRow& x) { return -x.pairs_per_second; });
      out << " " << (r ? config_text(*r) + ", " + speed_text(r->pairs_per_second) : std::string("-")) << " |";
    }
    out << "\n";
  }
  out << "\n";
}

void write_iterations(const std::vector<AccuracyRow>& rows, std::ostream& out) {
  // The swept tolerance nearest to 1e-8 (in log scale): where the solvers are compared.
  double tolerance = 0;
  for (const AccuracyRow& r : rows) {
    if (tolerance == 0 || std::abs(std::log10(r.point.tolerance) + 8) < std::abs(std::log10(tolerance) + 8)) {
      tolerance = r.point.tolerance;
    }
  }
  std::map<std::pair<int, int>, std::pair<double, int>> mean;  // (regime, solver) -> (sum of means, count)
  std::map<std::pair<int, int>, int> worst;
  for (const AccuracyRow& r : rows) {
    if (r.point.tolerance != tolerance || r.point.precision != Precision::float64) continue;
    const std::pair<int, int> key{int(r.regime), int(r.point.solver)};
    mean[key].first += r.iterations_mean;
    mean[key].second += 1;
    worst[key] = std::max(worst[key], r.iterations_max);
  }
  out << "## Iterations per regime (double, tolerance " << format("%g", tolerance) << ")\n\n"
      << "Mean over the cases of the mean iterations per pair (GJK iterations plus EPA expansions); max over all "
         "pairs in parentheses.\n\n| regime | gjk | nesterov | polyak |\n|---|---|---|---|\n";
  for (Regime regime : {Regime::distant, Regime::close, Regime::overlap}) {
    bool any = false;
    std::string line = std::string("| ") + to_string(regime) + " |";
    for (Solver solver : {Solver::gjk, Solver::nesterov, Solver::polyak}) {
      const auto it = mean.find({int(regime), int(solver)});
      if (it == mean.end()) {
        line += " - |";
        continue;
      }
      any = true;
      line += " " + format("%.1f", it->second.first / it->second.second) + " (" +
              std::to_string(worst[{int(regime), int(solver)}]) + ") |";
    }
    if (any) out << line << "\n";
  }
  out << "\n";
}

}  // namespace

const char* const kAccuracyCsvHeader =
    "case,regime,solver,precision,tolerance,query,pairs,threads,reference,witness_measure,pairs_per_second,"
    "ns_per_pair,distance_error_median,distance_error_p99,distance_error_max,distance_relative_error_max,"
    "witness_error_median,witness_error_p99,witness_error_max,normal_error_median,normal_error_p99,"
    "normal_error_max,iterations_mean,iterations_max,scored_pairs,not_converged,non_finite,reference_check";

void write_accuracy_csv(const std::vector<AccuracyRow>& rows, std::ostream& out) {
  out << kAccuracyCsvHeader << '\n';
  for (const AccuracyRow& r : rows) {
    out << r.case_name << ',' << to_string(r.regime) << ',' << to_string(r.point.solver) << ','
        << precision_name(r.point.precision) << ',' << format("%g", r.point.tolerance) << ',' << to_string(r.level)
        << ',' << r.pairs << ',' << r.threads << ',' << r.reference << ',' << r.witness_measure << ','
        << format("%.6g", r.pairs_per_second) << ',' << format("%.6g", r.ns_per_pair);
    const auto stats = [&](const ErrorStats& s) {
      out << ',' << error_text(s.median) << ',' << error_text(s.p99) << ',' << error_text(s.max);
    };
    stats(r.distance);
    out << ',' << error_text(r.distance_relative_max);
    stats(r.witness);
    stats(r.normal);
    out << ',' << format("%.3f", r.iterations_mean) << ',' << r.iterations_max << ',' << r.scored << ','
        << r.not_converged << ',' << r.non_finite << ',' << error_text(r.reference_check) << '\n';
  }
}

void write_accuracy_summary(const std::vector<AccuracyRow>& rows, const SummaryContext& c, std::ostream& out) {
  out << "# batchcol accuracy: summary\n\n"
      << "Produced by `" << c.command << "`: " << c.pairs << " pairs per case and regime, " << c.threads
      << " threads, pairs/s = median of " << c.runs << " timed runs, at most " << c.max_iterations
      << " GJK iterations, closed forms off (the solvers are measured). Distance error = |signed distance - "
         "reference| in metres; relative error = distance error / scale, with the engine's precision scale = bounding radius a + bounding radius b + distance between the shapes' origins (the float tolerance floor is 16 eps x scale). "
         "All columns of every configuration: accuracy.csv. Where no closed form exists the reference is the gjk "
         "double run at tolerance 1e-12 (certified by its duality gap); that configuration is left out of the tables "
         "below, as it scores 0 against itself.\n\n";
  const auto groups = group_by_case(rows);
  write_done_when(groups, out);
  write_cheapest(groups, out);
  write_iterations(rows, out);
}

}  // namespace batchcol::cli
