// Purpose: unit tests of the report library: CSV quoting and unit-carrying headers, series files, pipeline layout, page assets.
#include "csv_text.hpp"
#include "report_assets.hpp"
#include "series_csv.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

using namespace trackflow;
using namespace trackflow::report;

TEST_CASE("csv fields are quoted per RFC 4180 with quotes doubled") {
  CHECK(csv_field("plain") == "plain");
  CHECK(csv_field("5 m") == "5 m");
  CHECK(csv_field("[0, 0, 10]") == "\"[0, 0, 10]\"");
  CHECK(csv_field("say \"hi\"") == "\"say \"\"hi\"\"\"");
  CHECK(csv_field("two\nlines") == "\"two\nlines\"");
}

TEST_CASE("units go into column names without characters a CSV reader trips on") {
  CHECK(unit_suffix("m") == "m");
  CHECK(unit_suffix("m/s") == "m_per_s");
  CHECK(unit_suffix("m/s2") == "m_per_s2");
  CHECK(unit_suffix("m^2/s^3") == "m2_per_s3");
  CHECK(unit_suffix("1/s") == "per_s");
  CHECK(unit_suffix("") == "");
  CHECK(unit_suffix("1") == "");
  CHECK(column_header("position_rmse", "m") == "position_rmse_m");
  CHECK(column_header("anees", "") == "anees");
  CHECK(column_header("kf.q", "m2/s3") == "kf.q_m2_per_s3");
}

TEST_CASE("numbers are written in full and missing values as empty cells") {
  CHECK(csv_number(0.1) == "0.1");
  CHECK(csv_number(1.0 / 3.0) == "0.333333333333");
  CHECK(csv_number(NAN).empty());
  CHECK(csv_number(INFINITY).empty());
}

TEST_CASE("a series file has units in its header and one row per step") {
  Series s;
  s.name = "ensemble";
  s.add_column("time", "s");
  s.add_column("position_rmse", "m");
  s.add_column("anees");
  s.values = {0.0, NAN, NAN, 0.1, 2.5, 1.01};
  const auto dir = std::filesystem::temp_directory_path() / "tf_test_report";
  const std::string path = (dir / series_file_name("score", s)).string();
  CHECK(series_file_name("track", Series{"estimate:kf", "", {}, {}}) == "track.estimate-kf.csv");
  write_series_csv(path, s);
  std::ifstream f(path);
  std::stringstream text;
  text << f.rdbuf();
  CHECK(text.str() == "time_s,position_rmse_m,anees\n0,,\n0.1,2.5,1.01\n");
  std::filesystem::remove_all(dir);
}

TEST_CASE("the inlined chart library is the vendored Vega and Vega-Lite") {
  CHECK(vega_js().size() > 400000);
  CHECK(vega_lite_js().size() > 200000);
  CHECK(vega_js().find("t.version=\"6.2.0\"") != std::string_view::npos);
  // Nothing in the inlined code may close the <script> element it sits in.
  CHECK(vega_js().find("</script") == std::string_view::npos);
  CHECK(vega_lite_js().find("</script") == std::string_view::npos);
  CHECK(vega_lite_js().find("sourceMappingURL") == std::string_view::npos);
}
