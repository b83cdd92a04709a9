// Result output: exact CSV header, one row per pair, NaN as empty field / null, exact round trip of numbers.
#include "batchcol/io.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdlib>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace batchcol {
namespace {

using ::testing::HasSubstr;

constexpr const char* kHeader = "pair,status,collide,distance,pa_x,pa_y,pa_z,pb_x,pb_y,pb_z,n_x,n_y,n_z,iterations";
const double kNaN = std::numeric_limits<double>::quiet_NaN();

// Pair 0: separated with witness points; pair 1: overlapping at boolean level (everything else NaN);
// pair 2: invalid input.
PairResults sample_results() {
  PairResults r;
  r.status = {Status::converged, Status::max_iterations, Status::invalid_input};
  r.collide = {0, 1, 0};
  r.distance = {0.1 + 0.2, kNaN, kNaN};
  r.witness_a.push_back({1.0, -2.5, 1e-300});
  r.witness_b.push_back({1.0, -2.5, 0.30000000000000004});
  r.normal.push_back({0.0, 0.0, 1.0});
  for (int i = 0; i < 2; ++i) {
    r.witness_a.push_back({kNaN, kNaN, kNaN});
    r.witness_b.push_back({kNaN, kNaN, kNaN});
    r.normal.push_back({kNaN, kNaN, kNaN});
  }
  r.iterations = {7, 128, 0};
  return r;
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// Digits of the mantissa without leading zeros, e.g. "-0.0125e3" -> 3.
int significant_digits(const std::string& number) {
  int count = 0;
  bool leading = true;
  for (char c : number.substr(0, number.find_first_of("eE"))) {
    if (c < '0' || c > '9') continue;
    leading = leading && c == '0';
    count += leading ? 0 : 1;
  }
  return count;
}

TEST(ResultsOutput, CsvHasHeaderAndOneRowPerPair) {
  std::ostringstream out;
  write_results_csv(sample_results(), out);
  const auto lines = lines_of(out.str());
  ASSERT_EQ(lines.size(), 4u);
  EXPECT_EQ(lines[0], kHeader);
  EXPECT_EQ(lines[1], "0,converged,0,0.30000000000000004,1,-2.5,1e-300,1,-2.5,0.30000000000000004,0,0,1,7");
  EXPECT_EQ(lines[2], "1,max_iterations,1,,,,,,,,,,,128");
  EXPECT_EQ(lines[3], "2,invalid_input,0,,,,,,,,,,,0");
}

TEST(ResultsOutput, CsvNumbersRoundTripExactly) {
  PairResults r = sample_results();
  const double values[] = {1.0 / 3.0, -std::nextafter(1.0, 2.0), 6.02214076e23, -4.9e-324};
  r.distance[0] = values[0];
  r.witness_a.x[0] = values[1];
  r.witness_a.y[0] = values[2];
  r.witness_a.z[0] = values[3];
  std::ostringstream out;
  write_results_csv(r, out);
  std::istringstream row(lines_of(out.str())[1]);
  std::vector<std::string> fields;
  for (std::string field; std::getline(row, field, ',');) fields.push_back(field);
  ASSERT_EQ(fields.size(), 14u);
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(std::strtod(fields[3 + k].c_str(), nullptr), values[k]) << fields[3 + k];
    EXPECT_LE(significant_digits(fields[3 + k]), 17) << fields[3 + k];
  }
}

TEST(ResultsOutput, EmptyResultsGiveHeaderOnly) {
  std::ostringstream out;
  write_results_csv(PairResults{}, out);
  EXPECT_EQ(out.str(), std::string(kHeader) + "\n");
  std::ostringstream json;
  write_results_json(PairResults{}, json);
  EXPECT_EQ(nlohmann::json::parse(json.str()), nlohmann::json::parse(R"({"results":[]})"));
}

TEST(ResultsOutput, JsonHasOneObjectPerPairWithNullForMissingValues) {
  std::ostringstream out;
  write_results_json(sample_results(), out);
  const nlohmann::json doc = nlohmann::json::parse(out.str());
  ASSERT_TRUE(doc.is_object());
  ASSERT_EQ(doc.size(), 1u);
  const nlohmann::json& rows = doc.at("results");
  ASSERT_EQ(rows.size(), 3u);

  const nlohmann::json& r0 = rows[0];
  EXPECT_EQ(r0.size(), 14u);
  EXPECT_EQ(r0.at("pair"), 0);
  EXPECT_EQ(r0.at("status"), "converged");
  EXPECT_EQ(r0.at("collide"), 0);
  EXPECT_EQ(r0.at("distance").get<double>(), 0.1 + 0.2);
  EXPECT_EQ(r0.at("pa_z").get<double>(), 1e-300);
  EXPECT_EQ(r0.at("pb_z").get<double>(), 0.30000000000000004);
  EXPECT_EQ(r0.at("n_z").get<double>(), 1.0);
  EXPECT_EQ(r0.at("iterations"), 7);

  const nlohmann::json& r1 = rows[1];
  EXPECT_EQ(r1.at("pair"), 1);
  EXPECT_EQ(r1.at("status"), "max_iterations");
  EXPECT_EQ(r1.at("collide"), 1);
  for (const char* key : {"distance", "pa_x", "pa_y", "pa_z", "pb_x", "pb_y", "pb_z", "n_x", "n_y", "n_z"}) {
    EXPECT_TRUE(r1.at(key).is_null()) << key;
  }
  EXPECT_EQ(rows[2].at("status"), "invalid_input");
}

TEST(ResultsOutput, InfiniteDistanceIsNullInJson) {
  PairResults r = sample_results();
  r.distance[0] = std::numeric_limits<double>::infinity();
  std::ostringstream json;
  write_results_json(r, json);
  EXPECT_TRUE(nlohmann::json::parse(json.str())["results"][0]["distance"].is_null());
  std::ostringstream csv;
  write_results_csv(r, csv);
  EXPECT_THAT(lines_of(csv.str())[1], HasSubstr(",0,inf,"));
}

TEST(ResultsOutput, MismatchedArraySizesAreRejected) {
  PairResults r = sample_results();
  r.iterations.pop_back();
  std::ostringstream out;
  EXPECT_THROW(write_results_csv(r, out), InputError);
  EXPECT_THROW(write_results_json(r, out), InputError);
  EXPECT_TRUE(out.str().empty());  // nothing written before the check
}

// A boolean query leaves the distance, witness and normal arrays empty: their columns are empty / null. Empty is
// allowed per array, but an array's x, y, z must agree.
TEST(ResultsOutput, ArraysALevelDidNotComputeAreEmptyFields) {
  PairResults r = sample_results();
  r.distance.clear();
  for (Vec3Array* v : {&r.witness_a, &r.witness_b, &r.normal}) v->resize(0);
  std::ostringstream csv, json;
  write_results_csv(r, csv);
  const auto lines = lines_of(csv.str());
  ASSERT_EQ(lines.size(), 4u);
  EXPECT_EQ(lines[1], "0,converged,0,,,,,,,,,,,7");
  EXPECT_EQ(lines[2], "1,max_iterations,1,,,,,,,,,,,128");
  write_results_json(r, json);
  const auto parsed = nlohmann::json::parse(json.str()).at("results");
  ASSERT_EQ(parsed.size(), 3u);
  EXPECT_TRUE(parsed[0]["distance"].is_null());
  EXPECT_TRUE(parsed[0]["n_z"].is_null());
  EXPECT_EQ(parsed[0]["iterations"], 7);

  PairResults torn = sample_results();
  torn.normal.x.clear();  // y and z still full
  std::ostringstream out;
  EXPECT_THROW(write_results_csv(torn, out), InputError);
  EXPECT_TRUE(out.str().empty());
}

TEST(Names, RoundTripAndListValidNames) {
  for (const char* name : {"boolean", "distance", "witness", "penetration"}) {
    EXPECT_STREQ(to_string(parse_query_level(name)), name);
  }
  for (const char* name : {"gjk", "nesterov", "polyak", "automatic"}) EXPECT_STREQ(to_string(parse_solver(name)), name);
  EXPECT_EQ(parse_precision("double"), Precision::float64);
  EXPECT_EQ(parse_precision("float"), Precision::float32);
  EXPECT_STREQ(to_string(Precision::float32), "float");
  EXPECT_STREQ(to_string(Status::max_iterations), "max_iterations");
  EXPECT_STREQ(to_string(ShapeType::halfspace), "halfspace");
  EXPECT_STREQ(to_string(ShapeType::ellipsoid), "ellipsoid");
  try {
    parse_solver("GJK");
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("'GJK'"));
    EXPECT_THAT(e.what(), HasSubstr("gjk, nesterov, polyak"));
  }
  EXPECT_THROW(parse_precision("float64"), InputError);
  EXPECT_THROW(parse_query_level(""), InputError);
}

}  // namespace
}  // namespace batchcol
