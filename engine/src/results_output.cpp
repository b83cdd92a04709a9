// Result output as CSV or JSON, one row per pair in input order. Numbers are written in the shortest form that
// reads back to the same double (at most 17 significant digits), so output round-trips exactly.
#include "batchcol/io.hpp"

#include <charconv>
#include <cmath>
#include <limits>
#include <ostream>
#include <string>

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

}  // namespace

void write_results_csv(const PairResults& results, std::ostream& out) {
  check_sizes(results);
  std::string line;
  for (std::size_t c = 0; c < std::size(kColumns); ++c) line += (c ? "," : "") + std::string(kColumns[c]);
  line += '\n';
  out << line;
  for (std::size_t i = 0; i < results.size(); ++i) {
    line = std::to_string(i);
    append_row_values(line, results, i, false);
    line += '\n';
    out.write(line.data(), static_cast<std::streamsize>(line.size()));
  }
}

void write_results_json(const PairResults& results, std::ostream& out) {
  check_sizes(results);
  out << "{\"results\":[";
  std::string line;
  for (std::size_t i = 0; i < results.size(); ++i) {
    line = i ? ",\n" : "\n";
    line += "{\"pair\":" + std::to_string(i);
    append_row_values(line, results, i, true);
    line += '}';
    out.write(line.data(), static_cast<std::streamsize>(line.size()));
  }
  out << "\n]}\n";
}

}  // namespace batchcol
