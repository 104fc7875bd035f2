// Purpose: unit tests of the report library: CSV quoting and unit-carrying headers, series files, pipeline layout, page assets, the multi-target scene picture.
#include "charts.hpp"
#include "csv_text.hpp"
#include "report_assets.hpp"
#include "script_json.hpp"
#include "series_csv.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

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

TEST_CASE("scene picture: truth and track lines, all detections") {
  SceneView v;
  v.clutter.label = "clutter";
  v.target_detections.label = "target detections";
  for (int k = 0; k < 3000; ++k) {  // more than a line's 1500 points: the recorder caps, the page does not thin
    v.clutter.x.push_back(k);
    v.clutter.y.push_back(-k);
  }
  v.target_detections.x = {0, 1};
  v.target_detections.y = {0, 1};
  v.truths.push_back(Line{"truth 0", {0, 1, 2}, {0, 0, 0}});
  TrackPath t;
  t.id = 12;
  t.tentative = Line{"", {0, 1}, {1, 1}};
  t.confirmed = Line{"", {1, 2, 3}, {1, 1, 1}};
  v.tracks.push_back(t);
  TrackPath never;  // a track that stayed tentative: no confirmed line
  never.id = 13;
  never.tentative = Line{"", {5, 6}, {5, 6}};
  v.tracks.push_back(never);
  const Chart c = scene_chart("scene", v);
  auto attr = [&](const std::string& name) {
    for (const auto& [n, value] : c.attributes)
      if (n == name) return value;
    return std::string("missing");
  };
  CHECK(attr("data-truth-lines") == "1");
  CHECK(attr("data-track-lines") == "1");
  CHECK(attr("data-clutter-points") == "3000");
  CHECK(attr("data-target-detections") == "2");
  CHECK(c.lines == 4);  // the truth, 12's tentative and confirmed parts, 13's tentative part
  CHECK(c.symbols == 3002);
  CHECK(c.caption == "equal scales on both axes");
}

TEST_CASE("scene picture: a track's colour depends on its id only") {
  CHECK(std::string(track_colour(3)) == track_colour(13));
  CHECK(std::string(track_colour(3)) != track_colour(4));
  CHECK(std::string(track_colour(0)) == "#1f77b4");
}

TEST_CASE("script-safe JSON has no < > or & and parses back the same") {
  const nlohmann::json j = {{"label", "imm.p_<!--<script>"}, {"t", "</script><b>&amp;-->"}, {"path", "a\\<b"}};
  const std::string safe = script_safe_json(j.dump());
  CHECK(safe.find('<') == std::string::npos);
  CHECK(safe.find('>') == std::string::npos);
  CHECK(safe.find('&') == std::string::npos);
  CHECK(nlohmann::json::parse(safe) == j);
}
