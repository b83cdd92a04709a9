// Result output as CSV or JSON, one row per pair in input order. Numbers are written in the shortest form that
// reads back to the same double (at most 17 significant digits), so output round-trips exactly.
#include "batchcol/derivatives.hpp"
#include "batchcol/io.hpp"

#include <charconv>
#include <cmath>
#include <limits>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

namespace batchcol {
namespace {

constexpr const char* kColumns[] = {"pair", "status", "collide", "distance", "pa_x", "pa_y", "pa_z",
                                    "pb_x", "pb_y", "pb_z", "n_x", "n_y", "n_z", "iterations"};

// The value arrays a query level did not compute are empty (PairResults); the others have one entry per pair.
void check_sizes(const PairResults& r) {
  const std::size_t n = r.size();
  const auto n_or_empty = [n](std::size_t size) { return size == n || size == 0; };
  const auto vec3 = [&](const Vec3Array& v) {
    return n_or_empty(v.x.size()) && v.y.size() == v.x.size() && v.z.size() == v.x.size();
  };
  const bool ok = r.collide.size() == n && r.iterations.size() == n && n_or_empty(r.distance.size()) &&
                  vec3(r.witness_a) && vec3(r.witness_b) && vec3(r.normal);
  if (!ok)
    throw InputError("results: the per-pair arrays have different sizes (expected " + std::to_string(n) +
                     ", or 0 for values not computed)");
}

double value_or_nan(const std::vector<double>& values, std::size_t i) {
  return values.empty() ? std::numeric_limits<double>::quiet_NaN() : values[i];
}

// Appends `x`; NaN (a value the query level did not compute) becomes `missing`. Infinities are written as
// inf/-inf in CSV and as null in JSON, which has no literal for them.
void append_number(std::string& line, double x, const char* missing, bool json) {
  if (std::isnan(x) || (json && std::isinf(x))) {
    line += missing;
    return;
  }
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), x);
  line.append(buffer, result.ptr);
}

// The 13 values after "pair" in column order; `json` selects quoting and the missing-value spelling.
void append_row_values(std::string& line, const PairResults& r, std::size_t i, bool json) {
  const char* missing = json ? "null" : "";
  const auto key = [&](std::size_t column) {
    line += ',';
    if (json) {
      line += '"';
      line += kColumns[column];
      line += "\":";
    }
  };
  key(1);
  if (json) line += '"';
  line += to_string(r.status[i]);
  if (json) line += '"';
  key(2);
  line += r.collide[i] ? '1' : '0';
  const auto at = [i](const std::vector<double>& v) { return value_or_nan(v, i); };
  const double values[] = {at(r.distance),    at(r.witness_a.x), at(r.witness_a.y), at(r.witness_a.z),
                           at(r.witness_b.x), at(r.witness_b.y), at(r.witness_b.z), at(r.normal.x),
                           at(r.normal.y),    at(r.normal.z)};
  for (std::size_t k = 0; k < 10; ++k) {
    key(3 + k);
    append_number(line, values[k], missing, json);
  }
  key(13);
  line += std::to_string(r.iterations[i]);
}

// Derivative columns (derivatives.hpp): d_status, the distance gradients g_a0..g_a5, g_b0..g_b5, then the 3x6
// Jacobians row by row (dpa_da_RC: d witness_a / d xi_a, row R, column C; dpa_db, dpb_da, dpb_db, dn_da, dn_db),
// then for smoothed0 the smoothed values s_distance, s_pa_*, s_pb_*, s_n_*. Without Jacobians (DerivativeOptions::
// jacobians false: their arrays are empty) the columns stop after the gradients.
bool has_jacobians(const DerivativeResults& d) { return d.witness_a_wrt_a.data.size() == 18 * d.size(); }

std::vector<std::string> derivative_columns(const DerivativeResults& d) {
  std::vector<std::string> names = {"d_status"};
  for (const char* body : {"a", "b"})
    for (int k = 0; k < 6; ++k) names.push_back(std::string("g_") + body + std::to_string(k));
  if (has_jacobians(d))
    for (const char* m : {"dpa_da_", "dpa_db_", "dpb_da_", "dpb_db_", "dn_da_", "dn_db_"})
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 6; ++c) names.push_back(m + std::to_string(r) + std::to_string(c));
  if (!d.smoothed_distance.empty())
    for (const char* v :
         {"s_distance", "s_pa_x", "s_pa_y", "s_pa_z", "s_pb_x", "s_pb_y", "s_pb_z", "s_n_x", "s_n_y", "s_n_z"})
      names.push_back(v);
  return names;
}

void append_derivatives(std::string& line, const DerivativeResults& d, std::size_t i, bool json,
                        const std::vector<std::string>& names) {
  std::size_t column = 0;
  const auto key = [&] {
    line += ',';
    if (json) line += '"' + names[column] + "\":";
    ++column;
  };
  key();
  line += json ? std::string("\"") + to_string(d.status[i]) + '"' : std::string(to_string(d.status[i]));
  const char* missing = json ? "null" : "";
  for (const Vec6Array* g : {&d.distance_gradient_a, &d.distance_gradient_b})
    for (int k = 0; k < 6; ++k) key(), append_number(line, g->data[k * d.size() + i], missing, json);
  if (has_jacobians(d))
    for (const Mat36Array* m : {&d.witness_a_wrt_a, &d.witness_a_wrt_b, &d.witness_b_wrt_a, &d.witness_b_wrt_b,
                                &d.normal_wrt_a, &d.normal_wrt_b})
      for (int k = 0; k < 18; ++k) key(), append_number(line, m->data[k * d.size() + i], missing, json);
  if (d.smoothed_distance.empty()) return;
  key(), append_number(line, d.smoothed_distance[i], missing, json);
  for (const Vec3Array* v : {&d.smoothed_witness_a, &d.smoothed_witness_b, &d.smoothed_normal})
    for (const std::vector<double>* c : {&v->x, &v->y, &v->z}) key(), append_number(line, (*c)[i], missing, json);
}

void check_derivative_sizes(const PairResults& r, const DerivativeResults* d) {
  if (!d) return;
  const std::size_t n = d->size();
  if (n != r.size())
    throw InputError("derivatives: " + std::to_string(n) + " pairs, the results have " + std::to_string(r.size()));
  // Every array read below must hold n pairs (Jacobians: all six or none; smoothed values: all or none).
  const auto fail = [](const char* field) {
    throw InputError(std::string("derivatives: ") + field + " does not hold one entry per pair");
  };
  if (d->distance_gradient_a.data.size() != 6 * n) fail("distance_gradient_a");
  if (d->distance_gradient_b.data.size() != 6 * n) fail("distance_gradient_b");
  if (has_jacobians(*d)) {
    const std::pair<const Mat36Array*, const char*> matrices[] = {
        {&d->witness_a_wrt_b, "witness_a_wrt_b"}, {&d->witness_b_wrt_a, "witness_b_wrt_a"},
        {&d->witness_b_wrt_b, "witness_b_wrt_b"}, {&d->normal_wrt_a, "normal_wrt_a"},
        {&d->normal_wrt_b, "normal_wrt_b"}};
    for (const auto& [m, name] : matrices)
      if (m->data.size() != 18 * n) fail(name);
  }
  if (!d->smoothed_distance.empty()) {
    if (d->smoothed_distance.size() != n) fail("smoothed_distance");
    for (const auto& [v, name] : {std::pair<const Vec3Array*, const char*>{&d->smoothed_witness_a, "smoothed_witness_a"},
                                  {&d->smoothed_witness_b, "smoothed_witness_b"},
                                  {&d->smoothed_normal, "smoothed_normal"}})
      if (v->x.size() != n || v->y.size() != n || v->z.size() != n) fail(name);
  }
}

}  // namespace

void write_results_csv(const PairResults& results, std::ostream& out, const DerivativeResults* derivatives) {
  check_sizes(results);
  check_derivative_sizes(results, derivatives);
  const std::vector<std::string> extra = derivatives ? derivative_columns(*derivatives) : std::vector<std::string>();
  std::string line;
  for (std::size_t c = 0; c < std::size(kColumns); ++c) line += (c ? "," : "") + std::string(kColumns[c]);
  for (const std::string& name : extra) line += ',' + name;
  line += '\n';
  out << line;
  for (std::size_t i = 0; i < results.size(); ++i) {
    line = std::to_string(i);
    append_row_values(line, results, i, false);
    if (derivatives) append_derivatives(line, *derivatives, i, false, extra);
    line += '\n';
    out.write(line.data(), static_cast<std::streamsize>(line.size()));
  }
}

void write_results_json(const PairResults& results, std::ostream& out, const DerivativeResults* derivatives) {
  check_sizes(results);
  check_derivative_sizes(results, derivatives);
  const std::vector<std::string> extra = derivatives ? derivative_columns(*derivatives) : std::vector<std::string>();
  out << "{\"results\":[";
  std::string line;
  for (std::size_t i = 0; i < results.size(); ++i) {
    line = i ? ",\n" : "\n";
    line += "{\"pair\":" + std::to_string(i);
    append_row_values(line, results, i, true);
    if (derivatives) append_derivatives(line, *derivatives, i, true, extra);
    line += '}';
    out.write(line.data(), static_cast<std::streamsize>(line.size()));
  }
  out << "\n]}\n";
}

}  // namespace batchcol
