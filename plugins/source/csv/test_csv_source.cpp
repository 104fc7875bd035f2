// Purpose: tests of source.csv: unit conversion, both frames, optional columns, every bad-data case, skip mode, column suggestions.
#include <trackflow/host/plugins.hpp>

#include <catch2/catch.hpp>

#include <sys/stat.h>

#include "plugin_fixture.hpp"

#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <unistd.h>

using namespace trackflow;
namespace fs = std::filesystem;

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// A fresh folder per test, removed at the end.
class TempDir {
 public:
  TempDir() {
    static std::atomic<int> counter{0};
    path_ = fs::temp_directory_path() /
            ("trackflow_csv_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  // Writes `text` byte for byte (no newline translation) and returns the file's path.
  std::string write(const std::string& name, const std::string& text) const {
    const fs::path p = path_ / name;
    fs::create_directories(p.parent_path());
    std::ofstream(p, std::ios::binary) << text;
    return p.string();
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

std::string yaml_params(const std::string& file, const std::string& extra = "") {
  return "{path: '" + file + "'" + (extra.empty() ? "" : ", " + extra) + "}";
}

std::vector<Measurement> read_all(const std::string& file, const std::string& extra = "", Diagnostics* diag = nullptr) {
  auto src = test::make("source.csv", yaml_params(file, extra));
  test::Collector out;
  out.attach_to(*src);
  test::drain(*src, 1, 0, diag);
  return out.measurements;
}

// The DataError message of reading `text`, or "" if it was read without an error.
std::string data_error(const TempDir& dir, const std::string& name, const std::string& text,
                       const std::string& extra = "") {
  const std::string file = dir.write(name, text);
  try {
    (void)test::make("source.csv", yaml_params(file, extra));
  } catch (const DataError& e) {
    return e.what();
  }
  return "";
}

void check_finite(const Measurement& m) {
  CHECK(std::isfinite(m.time));
  for (int i = 0; i < m.value.size(); ++i) CHECK(std::isfinite(m.value(i)));
  for (int i = 0; i < m.covariance.size(); ++i) CHECK(std::isfinite(m.covariance.data()[i]));
}

}  // namespace

// spherical rows are converted from km, degrees and milliseconds to SI
TEST_CASE("spherical rows in km/deg/ms are converted to SI") {
  TempDir dir;
  const std::string file = dir.write("log.csv",
                                     "time,range,azimuth,elevation\n"
                                     "1500,12.5,90,10\n"
                                     "2500,13,-190,-5\n"
                                     "2500,13.25,180,0\n");
  const auto ms = read_all(file, "time_unit: ms, range_unit: km, angle_unit: deg, sigma_range: 20 m, "
                                 "sigma_azimuth: 2 mrad, position: [1 km, -2 km, 30 m], sensor_id: 7");
  REQUIRE(ms.size() == 3);
  CHECK(ms[0].time == Approx(1.5));
  CHECK(ms[0].value(0) == Approx(12500.0));
  CHECK(ms[0].value(1) == Approx(std::numbers::pi / 2));
  CHECK(ms[0].value(2) == Approx(10 * kDeg));
  // -190 deg is the same direction as +170 deg; azimuths come wrapped to (-pi, pi].
  CHECK(ms[1].value(1) == Approx(170 * kDeg));
  CHECK(ms[1].value(2) == Approx(-5 * kDeg));
  CHECK(ms[2].time == ms[1].time);  // equal times are allowed
  CHECK(ms[2].value(1) == Approx(std::numbers::pi));
  for (const auto& m : ms) {
    CHECK(m.frame == Frame::Spherical);
    CHECK(m.sensor == 7u);
    CHECK(m.sensor_position.isApprox(Vec3(1000, -2000, 30)));
    CHECK_FALSE(m.has_range_rate);
    CHECK_FALSE(m.has_snr);
    CHECK(m.valid);
    CHECK(m.mode == MeasMode::Unknown);
    REQUIRE(m.value.size() == 3);
    REQUIRE(m.covariance.rows() == 3);
    CHECK(m.covariance(0, 0) == Approx(400.0));
    CHECK(m.covariance(1, 1) == Approx(4e-6));
    CHECK(m.covariance(2, 2) == Approx(1e-6));  // default 1 mrad
    CHECK(m.covariance(0, 1) == 0.0);
    check_finite(m);
  }
}

TEST_CASE("angles in rad/mrad with range and time in SI") {
  TempDir dir;
  const std::string file = dir.write("log.csv", "time,range,azimuth,elevation\n0.25,800,-1.5,0.2\n");
  const auto rad = read_all(file, "angle_unit: rad");
  REQUIRE(rad.size() == 1);
  CHECK(rad[0].time == 0.25);
  CHECK(rad[0].value(0) == 800.0);
  CHECK(rad[0].value(1) == Approx(-1.5));
  CHECK(rad[0].value(2) == Approx(0.2));
  const auto mrad = read_all(file, "angle_unit: mrad");
  CHECK(mrad.at(0).value(1) == Approx(-1.5e-3));
  CHECK(mrad.at(0).value(2) == Approx(0.2e-3));
}

// cartesian rows are positions in the ENU frame with an isotropic covariance
TEST_CASE("cartesian rows are ENU positions") {
  TempDir dir;
  const std::string file = dir.write("xyz.csv",
                                     "t,east,north,up,rdot\n"
                                     "1,1.5,-2,0.25,-0.1\n"
                                     "2,1.6,-2.1,0.3,-0.2\n");
  const auto ms = read_all(file, "frame: cartesian, time_column: t, x_column: east, y_column: north, z_column: up, "
                                 "position_unit: km, sigma_position: 5 m, range_rate_column: rdot, "
                                 "sigma_range_rate: 2 m/s, azimuth_convention: x_counterclockwise");
  REQUIRE(ms.size() == 2);
  CHECK(ms[0].frame == Frame::Cartesian);
  CHECK(ms[0].azimuth == AzimuthConvention::XCounterClockwise);
  REQUIRE(ms[0].value.size() == 4);
  CHECK(ms[0].value(0) == Approx(1500));
  CHECK(ms[0].value(1) == Approx(-2000));
  CHECK(ms[0].value(2) == Approx(250));
  CHECK(ms[0].has_range_rate);
  CHECK(ms[0].value(3) == Approx(-100));  // km/s with position_unit km
  CHECK(ms[1].value(3) == Approx(-200));
  REQUIRE(ms[0].covariance.rows() == 4);
  for (int i = 0; i < 3; ++i) CHECK(ms[0].covariance(i, i) == Approx(25.0));
  CHECK(ms[0].covariance(3, 3) == Approx(4.0));
  CHECK(ms[0].covariance(0, 3) == 0.0);
}

// optional columns: range rate, SNR, mode, validity, sensor; extra columns and quotes; CRLF
TEST_CASE("optional and extra columns with quotes and CRLF") {
  TempDir dir;
  const std::string file = dir.write("opt.csv",
                                     "\"time\",range,azimuth,elevation,rr,snr,mode,ok,radar,comment\r\n"
                                     "0,1000,0,0,-12.5,17.5,Beacon,1,3,first\r\n"
                                     "1,1001,1,1,-12,\"16\",SKIN,false,4,\"quoted\"\r\n"
                                     "2,1002,2,2,-11.5,15,search,TRUE,5,\r\n"
                                     "3,1003,3,3,+4,-2.5,,0,6,last\r\n");
  const auto ms = read_all(file, "range_rate_column: rr, snr_column: snr, mode_column: mode, valid_column: ok, "
                                 "sensor_column: radar, sigma_range_rate: 0.5 m/s");
  REQUIRE(ms.size() == 4);
  CHECK(ms[0].mode == MeasMode::Beacon);
  CHECK(ms[1].mode == MeasMode::Skin);
  CHECK(ms[2].mode == MeasMode::Unknown);
  CHECK(ms[3].mode == MeasMode::Unknown);
  CHECK(ms[0].valid);
  CHECK_FALSE(ms[1].valid);
  CHECK(ms[2].valid);
  CHECK_FALSE(ms[3].valid);
  const double rr[] = {-12.5, -12, -11.5, 4}, snr[] = {17.5, 16, 15, -2.5};
  for (int i = 0; i < 4; ++i) {
    CHECK(ms[i].sensor == static_cast<std::uint32_t>(3 + i));
    CHECK(ms[i].has_snr);
    CHECK(ms[i].snr_db == snr[i]);
    CHECK(ms[i].has_range_rate);
    REQUIRE(ms[i].value.size() == 4);
    CHECK(ms[i].value(3) == rr[i]);
    CHECK(ms[i].covariance(3, 3) == Approx(0.25));
    CHECK(ms[i].time == i);
    CHECK(ms[i].value(0) == 1000 + i);
  }
}

// emits one measurement per call in file order; start_run rewinds
TEST_CASE("one measurement per call in order and rewind") {
  TempDir dir;
  const std::string file = dir.write("log.csv", "time,range,azimuth,elevation\n0,1,0,0\n0.5,2,0,0\n2,3,0,0\n");
  auto src = test::make("source.csv", yaml_params(file));
  auto& gen = dynamic_cast<Generator&>(*src);
  test::Collector out;
  out.attach_to(*src);
  Diagnostics diag;
  for (std::uint64_t run = 0; run < 2; ++run) {
    src->start_run({run, 1, &diag});
    const double expected[] = {0, 0.5, 2};
    for (int i = 0; i < 3; ++i) {
      CHECK(gen.next_time() == expected[i]);
      const std::size_t before = out.measurements.size();
      gen.emit_next();
      CHECK(out.measurements.size() == before + 1);
      CHECK(out.measurements.back().value(0) == i + 1);
    }
    CHECK(std::isinf(gen.next_time()));
    CHECK(gen.next_time() > 0);
  }
  CHECK(diag.skips.empty());
}

// blank lines at the end and a complete last line without newline are accepted
TEST_CASE("trailing blank lines and missing final newline") {
  TempDir dir;
  CHECK(read_all(dir.write("a.csv", "time,range,azimuth,elevation\n0,1,0,0\n1,2,0,0\n\n  \r\n\n")).size() == 2);
  CHECK(read_all(dir.write("b.csv", "time,range,azimuth,elevation\n0,1,0,0\n1,2,0,0")).size() == 2);
  CHECK(read_all(dir.write("c.csv", "time,range,azimuth,elevation\r\n0,1,0,0\r\n1,2,0,0")).size() == 2);
}

// each kind of bad row is a DataError naming the file and the line
TEST_CASE("bad rows are DataErrors naming file and line") {
  TempDir dir;
  const std::string header = "time,range,azimuth,elevation\n";
  struct Case {
    const char* name;
    std::string text;
    const char* line;  // "file:LINE:"
    const char* says;
  };
  const std::vector<Case> cases = {
      {"nonnumeric.csv", header + "0,1000,0,0\n1,abc,0,0\n", ":3:", "not a number (column range, value 'abc')"},
      {"nan.csv", header + "0,1000,0,0\n1,1000,NaN,0\n2,1000,0,0\n", ":3:", "NaN or infinite value (column azimuth"},
      {"inf.csv", header + "0,1000,0,0\n1,1000,0,0\n2,1000,0,-inf\n", ":4:", "column elevation, value '-inf'"},
      {"huge.csv", header + "0,1e999,0,0\n", ":2:", "number is too large for a double (beyond +-1.8e308) (column range"},
      {"tiny.csv", header + "1e-400,1000,0,0\n", ":2:", "number is too small for a double (nonzero but below"},
      {"spin.csv", header + "0,1000,1e300,0\n", ":2:", "azimuth beyond +-360 deg (column azimuth"},
      {"fields.csv", header + "0,1000,0,0\n1,1000,0,0,9\n2,1000,0,0\n", ":3:", "wrong number of fields"},
      {"fewer.csv", header + "0,1000,0,0\n1,1000,0\n2,1000,0,0\n", ":3:", "expected 4 fields as in the header"},
      {"negative.csv", header + "0,1000,0,0\n1,-5,0,0\n", ":3:", "negative range (column range, value '-5')"},
      {"backwards.csv", header + "0,1000,0,0\n2,1000,0,0\n2,1000,0,0\n1.5,1000,0,0\n", ":5:",
       "time goes backwards: earlier than 2 on line 4 (column time, value '1.5')"},
      {"truncated.csv", header + "0,1000,0,0\n1,1000,0,0\n2,10\n", ":4:", "truncated last line"},
      {"cut.csv", header + "0,1000,0,0\n1,1000,0,", ":3:", "the last line looks truncated (no newline"},
      {"cut_quote.csv", header + "0,1000,0,0\n1,1000,0,\"0.", ":3:", "the last line looks truncated"},
      {"blank_inside.csv", header + "0,1000,0,0\n\n1,1000,0,0\n", ":3:", "empty line inside the data"},
      {"empty_cell.csv", header + "0,,0,0\n", ":2:", "empty value where a number is expected (column range"},
      {"elevation.csv", header + "0,1000,0,95\n", ":2:", "elevation beyond"},
      {"header_only.csv", header, ":1:", "header but no data rows"},
      {"header_only_blank.csv", header + "\n\n", ":1:", "header but no data rows"},
  };
  for (const auto& c : cases) {
    INFO(c.name);
    const std::string message = data_error(dir, c.name, c.text);
    CHECK_THAT(message, Catch::Matchers::Contains(std::string(c.name) + c.line));
    CHECK_THAT(message, Catch::Matchers::Contains(c.says));
  }
  SECTION("an empty file") {
    for (const char* text : {"", "\n\n", "  \r\n"}) {
      const std::string message = data_error(dir, "empty.csv", text);
      CHECK_THAT(message, Catch::Matchers::Contains("empty.csv"));
      CHECK_THAT(message, Catch::Matchers::Contains("empty"));
    }
  }
  SECTION("the same data rows become good when fixed") {
    CHECK(data_error(dir, "good.csv", header + "0,1000,0,0\n1,1000,0,0\n").empty());
  }
}

// on_bad_row: skip leaves out exactly the bad rows and reports each once
TEST_CASE("on_bad_row skip drops and reports each bad row") {
  TempDir dir;
  const std::string file = dir.write("mixed.csv",
                                     "time,range,azimuth,elevation\n"  // 1
                                     "0,100,0,0\n"                     // 2 good
                                     "1,abc,0,0\n"                     // 3 not a number
                                     "2,200,0,0\n"                     // 4 good
                                     "3,-1,0,0\n"                      // 5 negative range
                                     "1.5,300,0,0\n"                   // 6 backwards (after 2 s)
                                     "4,400,nan,0\n"                   // 7 nan
                                     "5,500,0,0\n"                     // 8 good
                                     "6,600,0\n");                     // 9 truncated last line
  auto src = test::make("source.csv", yaml_params(file, "on_bad_row: skip"), "radar");
  test::Collector out;
  out.attach_to(*src);
  Diagnostics run0, run1;
  test::drain(*src, 1, 0, &run0);
  REQUIRE(out.measurements.size() == 3);
  CHECK(out.measurements[0].value(0) == 100);
  CHECK(out.measurements[1].value(0) == 200);
  CHECK(out.measurements[2].value(0) == 500);
  REQUIRE(run0.skips.size() == 5);
  const char* lines[] = {":3:", ":5:", ":6:", ":7:", ":9:"};
  for (int i = 0; i < 5; ++i) {
    CHECK(run0.skips[i].node == "radar");
    CHECK_THAT(run0.skips[i].message, Catch::Matchers::Contains(std::string("mixed.csv") + lines[i]));
  }
  // Later runs replay the same rows without counting the skips again.
  test::drain(*src, 2, 1, &run1);
  CHECK(run1.skips.empty());
  CHECK(out.measurements.size() == 6);

  Summary summary;
  src->finish(summary, {"radar", "", 2});
  REQUIRE(summary.find("rows"));
  REQUIRE(summary.find("skipped_rows"));
  CHECK(summary.find("rows")->value == 8);
  CHECK(summary.find("skipped_rows")->value == 5);
}

// an empty file or a header without rows is an error even with on_bad_row: skip
TEST_CASE("an empty file is an error even with skip") {
  TempDir dir;
  CHECK_THAT(data_error(dir, "e.csv", "", "on_bad_row: skip"), Catch::Matchers::Contains("e.csv"));
  CHECK_THAT(data_error(dir, "h.csv", "time,range,azimuth,elevation\n", "on_bad_row: skip"),
             Catch::Matchers::Contains("h.csv:1:"));
}

// a missing column names the file, the header line and the columns, and suggests the close name
TEST_CASE("a missing column is named with a suggestion") {
  TempDir dir;
  const std::string message = data_error(dir, "cols.csv", "time,rnage,azimuth,Elevation\n0,1,0,0\n");
  CHECK_THAT(message, Catch::Matchers::Contains("cols.csv:1:"));
  CHECK_THAT(message, Catch::Matchers::Contains("no column 'range' (range_column)"));
  CHECK_THAT(message, Catch::Matchers::Contains("did you mean 'rnage'"));
  CHECK_THAT(message, Catch::Matchers::Contains("'time', 'rnage', 'azimuth', 'Elevation'"));

  const std::string case_only = data_error(dir, "cols2.csv", "time,range,azimuth,Elevation\n0,1,0,0\n");
  CHECK_THAT(case_only, Catch::Matchers::Contains("did you mean 'Elevation'"));

  const std::string optional = data_error(dir, "cols3.csv", "time,range,azimuth,elevation\n0,1,0,0\n", "snr_column: SNR");
  CHECK_THAT(optional, Catch::Matchers::Contains("no column 'SNR' (snr_column)"));
  // Nothing close: no suggestion, but the list of columns.
  const std::string far = data_error(dir, "cols4.csv", "a,b,c,d\n0,1,0,0\n");
  CHECK_THAT(far, Catch::Matchers::Contains("no column 'time'"));
  CHECK_THAT(far, !Catch::Matchers::Contains("did you mean"));
}

TEST_CASE("bad cells in the optional columns") {
  TempDir dir;
  const std::string header = "time,range,azimuth,elevation,ok,sensor,snr\n";
  const std::string opts = "valid_column: ok, sensor_column: sensor, snr_column: snr";
  CHECK_THAT(data_error(dir, "v.csv", header + "0,1,0,0,yes,1,3\n", opts),
             Catch::Matchers::Contains("v.csv:2: not a validity flag (expected 1, 0, true or false) (column ok, value 'yes')"));
  CHECK_THAT(data_error(dir, "s.csv", header + "0,1,0,0,1,-2,3\n", opts),
             Catch::Matchers::Contains("s.csv:2: not a sensor id"));
  CHECK_THAT(data_error(dir, "n.csv", header + "0,1,0,0,1,2,inf\n", opts),
             Catch::Matchers::Contains("n.csv:2: NaN or infinite value (column snr"));
}

TEST_CASE("parameter mistakes are configuration errors") {
  TempDir dir;
  const std::string file = dir.write("log.csv", "time,range,azimuth,elevation\n0,1,0,0\n");
  CHECK_THROWS_AS(test::make("source.csv", yaml_params(file, "x_column: east")), ConfigError);
  CHECK_THROWS_AS(test::make("source.csv", yaml_params(file, "frame: cartesian, angle_unit: rad")), ConfigError);
  CHECK_THROWS_AS(test::make("source.csv", yaml_params(file, "sigma_range_rate: 2 m/s")), ConfigError);
  CHECK_THROWS_AS(test::make("source.csv", yaml_params(file, "sigma_range: 3 mrad")), ConfigError);
  try {
    (void)test::make("source.csv", yaml_params((dir.path() / "missing.csv").string()));
    FAIL("a missing file must be an error");
  } catch (const ConfigError& e) {
    CHECK_THAT(e.message(), Catch::Matchers::Contains("missing.csv"));
  }
}

// a relative path is relative to the folder of the pipeline file that wrote it
TEST_CASE("a relative path is relative to the pipeline file") {
  TempDir dir;
  const std::string pipeline = dir.write("pipelines/p.yaml", "# stands in for the pipeline file\n");
  dir.write("pipelines/data/rel.csv", "time,range,azimuth,elevation\n0,42,0,0\n");
  const Params given = test::params_for("source.csv", "{path: data/rel.csv}");
  Params p(given.node(), given.where());
  for (auto [name, value] : given.values()) {
    if (name == "path") value.where = {pipeline, 3, 5};
    p.set(name, value);
  }
  const auto& reg = test::registry();
  auto src = reg.create(*reg.find("source.csv"), p);
  test::Collector out;
  out.attach_to(*src);
  test::drain(*src);
  REQUIRE(out.measurements.size() == 1);
  CHECK(out.measurements[0].value(0) == 42);
}

// a file that is not a log: no line of it is quoted beyond the offending token
TEST_CASE("a file that is not a log is not quoted") {
  TempDir dir;
  const std::string secret = "root:x:0:0:root:/root:/bin/bash";
  const std::string message = data_error(dir, "passwd", secret + "\ndaemon:x:1:1::/usr/sbin:/usr/sbin/nologin\n");
  CHECK_THAT(message, Catch::Matchers::Contains("does not look like a header"));
  CHECK_THAT(message, !Catch::Matchers::Contains("root:x"));
  CHECK_THAT(message, !Catch::Matchers::Contains("daemon"));
  // A long cell is cut: the message never carries a whole line.
  const std::string long_cell(5000, 'z');
  const std::string cut = data_error(dir, "long.csv", "time,range,azimuth,elevation\n0," + long_cell + ",0,0\n");
  CHECK_THAT(cut, Catch::Matchers::Contains("not a number"));
  CHECK(cut.size() < 400);
}

// finite in the file's unit is not enough: the value must be finite in SI
TEST_CASE("a value that overflows in SI is a bad row") {
  TempDir dir;
  const std::string message =
      data_error(dir, "km.csv", "time,range,azimuth,elevation\n0,1e306,0,0\n", "range_unit: km");
  CHECK_THAT(message, Catch::Matchers::Contains("km.csv:2: value overflows when converted to SI (column range"));
  CHECK(data_error(dir, "km_ok.csv", "time,range,azimuth,elevation\n0,1e300,0,0\n", "range_unit: km").empty());
}

// only regular files are logs: a FIFO would block, a device never end
TEST_CASE("a path that is not a regular file is refused") {
  TempDir dir;
  const std::string fifo = (dir.path() / "fifo.csv").string();
  REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
  try {
    (void)test::make("source.csv", yaml_params(fifo));
    FAIL("a FIFO must be refused");
  } catch (const ConfigError& e) {
    CHECK_THAT(e.message(), Catch::Matchers::Contains("not a regular file"));
  }
}

// many bad rows with on_bad_row: skip keep a bounded list of messages and an exact count
TEST_CASE("many skipped rows keep a bounded message list") {
  TempDir dir;
  std::string text = "time,range,azimuth,elevation\n0,1,0,0\n";
  for (int i = 1; i <= 3000; ++i) text += std::to_string(i) + ",abc,0,0\n";
  const std::string file = dir.write("many.csv", text);
  auto src = test::make("source.csv", yaml_params(file, "on_bad_row: skip"), "radar");
  Diagnostics run0;
  test::drain(*src, 1, 0, &run0);
  CHECK(run0.skips.size() == 1001);
  CHECK_THAT(run0.skips.back().message, Catch::Matchers::Contains("2000 more bad rows"));
  Summary summary;
  src->finish(summary, {"radar", "", 1});
  CHECK(summary.find("skipped_rows")->value == 3000);
  CHECK(summary.find("rows")->value == 3001);
}

// a log many stream buffers long, with CRLF, bad rows and one line longer than the default buffer,
// replays the same rows in every run, from each instance
TEST_CASE("a long log is streamed again in every run") {
  TempDir dir;
  std::string text = "time,range,azimuth,elevation,note\r\n";
  std::vector<double> ranges;
  for (int i = 0; i < 30000; ++i) {
    const double range = 1000 + i;
    // Every 997th row is bad; row 15000 carries a note of 600 kB (beyond the 256 KiB buffer).
    if (i % 997 == 5) {
      text += std::to_string(i) + ",abc,0,0,x\r\n";
      continue;
    }
    text += std::to_string(i) + "," + std::to_string(range) + ",0.5,0.25," + (i == 15000 ? std::string(600000, 'n') : "y") + "\r\n";
    ranges.push_back(range);
  }
  const std::string file = dir.write("long.csv", text);
  auto first = test::make("source.csv", yaml_params(file, "on_bad_row: skip"), "radar");
  auto second = test::make("source.csv", yaml_params(file, "on_bad_row: skip"), "radar");
  for (auto* src : {first.get(), second.get()}) {
    test::Collector out;
    out.attach_to(*src);
    Diagnostics run0, run1;
    test::drain(*src, 1, 0, &run0);
    test::drain(*src, 1, 1, &run1);
    REQUIRE(out.measurements.size() == 2 * ranges.size());
    for (std::size_t k = 0; k < out.measurements.size(); ++k) {
      const Measurement& m = out.measurements[k];
      REQUIRE(m.value(0) == ranges[k % ranges.size()]);
      REQUIRE(m.value(2) == Approx(0.25 * kDeg));
    }
    CHECK(run0.skips.size() == 31);
    CHECK_THAT(run0.skips[0].message, Catch::Matchers::Contains("long.csv:7: not a number (column range, value 'abc')"));
    CHECK(run1.skips.empty());
    Summary summary;
    src->finish(summary, {"radar", "", 2});
    CHECK(summary.find("rows")->value == 30000);
    CHECK(summary.find("skipped_rows")->value == 31);
  }
}

// the rows are read again in each run: a log rewritten in place since the check is refused, while
// one replaced by a new file (renamed over it) replays what was checked
TEST_CASE("a log rewritten after the check is an error in the run") {
  TempDir dir;
  const std::string header = "time,range,azimuth,elevation\n";
  const std::string file = dir.write("log.csv", header + "0,100,0,0\n1,200,0,0\n");
  auto src = test::make("source.csv", yaml_params(file));
  test::Collector out;
  out.attach_to(*src);
  test::drain(*src, 1, 0);
  CHECK(out.measurements.size() == 2);

  SECTION("in place") {
    { std::ofstream(file, std::ios::binary | std::ios::app) << "2,abc,0,0\n"; }
    try {
      test::drain(*src, 1, 1);
      FAIL("a rewritten log must be refused");
    } catch (const DataError& e) {
      CHECK_THAT(e.what(), Catch::Matchers::Contains("log.csv: the file changed after it was checked"));
    }
  }
  SECTION("replaced") {
    const std::string other = dir.write("other.csv", header + "0,7,0,0\n");
    fs::rename(other, file);
    test::drain(*src, 1, 1);
    REQUIRE(out.measurements.size() == 4);
    CHECK(out.measurements[3].value(0) == 200);
  }
}

namespace {

struct RecordedScan {
  double time = 0.0;
  std::uint32_t sensor = 0;
  std::vector<Detection> detections;
  double pd = 0.0, density = 0.0;
};

class ScanRecorder final : public Component {
 public:
  void on_scan(const Scan& s, int) override {
    scans.push_back({s.time, s.sensor.sensor, {s.detections.begin(), s.detections.end()}, s.detection_probability, s.clutter_density});
  }
  std::vector<RecordedScan> scans;
};

// The message of whatever building source.csv on `file` with `extra` parameters throws ("" if none).
std::string refusal(const std::string& file, const std::string& extra) {
  try {
    (void)test::make("source.csv", yaml_params(file, extra));
  } catch (const std::exception& e) {
    return e.what();
  }
  return {};
}

std::vector<RecordedScan> read_scans(const std::string& file, const std::string& extra) {
  auto src = test::make("source.csv", yaml_params(file, "content: detections" + (extra.empty() ? "" : ", " + extra)));
  CHECK(src->produced_kinds() == mask(ItemKind::Scan));
  ScanRecorder rec;
  Link link{&rec, 0, 0xFF};
  src->out.connect(&link, 1);
  test::drain(*src);
  return rec.scans;
}

}  // namespace

// A detection log: rows of equal time are one look, a row without values a look that saw nothing,
// and the origin column labels each detection (target id, clutter, or unknown when empty).
TEST_CASE("content detections groups rows of equal time into scans") {
  TempDir dir;
  const std::string file = dir.write("plots.csv",
                                     "time,x,y,z,origin\n"
                                     "1,10,20,0,3\n"
                                     "1,-5,7,0,clutter\n"
                                     "2,,,,\n"
                                     "3,11,21,0,\n");
  const auto scans = read_scans(file, "frame: cartesian, origin_column: origin, detection_probability: 0.9");
  REQUIRE(scans.size() == 3);
  CHECK(scans[0].time == 1.0);
  REQUIRE(scans[0].detections.size() == 2);
  CHECK(scans[0].detections[0].value[0] == 10.0);
  CHECK(scans[0].detections[0].origin == 3);
  CHECK(scans[0].detections[1].origin == kOriginClutter);
  CHECK(scans[0].pd == 0.9);
  CHECK(std::isnan(scans[0].density));
  CHECK(scans[1].time == 2.0);
  CHECK(scans[1].detections.empty());  // looked, saw nothing
  REQUIRE(scans[2].detections.size() == 1);
  CHECK(scans[2].detections[0].origin == kOriginUnknown);
}

// With a scan column, consecutive rows of one scan number are one look at its first row's time,
// whatever their own times (a rotating radar time-stamps each plot).
TEST_CASE("content detections groups rows by the scan column") {
  TempDir dir;
  const std::string file = dir.write("plots.csv",
                                     "scan,time,range,azimuth,elevation\n"
                                     "7,1.00,1000,10,1\n"
                                     "7,1.25,2000,100,1\n"
                                     "8,2.00,1500,50,2\n");
  const auto scans = read_scans(file, "scan_column: scan");
  REQUIRE(scans.size() == 2);
  CHECK(scans[0].time == 1.0);
  REQUIRE(scans[0].detections.size() == 2);
  CHECK(scans[0].detections[1].value[1] == Approx(100 * kDeg));
  CHECK(scans[1].detections.size() == 1);
}

TEST_CASE("content detections refuses what does not belong to it") {
  TempDir dir;
  const std::string file = dir.write("plots.csv", "time,range,azimuth,elevation,valid,scan,origin\n1,1000,10,1,1,x,-2\n");
  CHECK_THAT(refusal(file, "scan_column: scan"), Catch::Contains("content: detections"));
  CHECK_THAT(refusal(file, "content: detections, valid_column: valid"), Catch::Contains("value cells are empty"));
  CHECK_THAT(refusal(file, "content: detections, scan_column: scan"), Catch::Contains("not a scan id"));
  CHECK_THAT(refusal(file, "content: detections, origin_column: origin"), Catch::Contains("not an origin"));
  // A measurement log emits measurements only.
  auto src = test::make("source.csv", yaml_params(file));
  CHECK(src->produced_kinds() == mask(ItemKind::Measurement));
}

// A truth log: one Truth per row, its target and velocity from their columns (km and km/s here).
TEST_CASE("content truth replays targets with their velocities") {
  TempDir dir;
  const std::string file = dir.write("truth.csv",
                                     "time,target,x,y,z,vx,vy,vz\n"
                                     "0,4,1,2,0.5,0.1,0,0\n"
                                     "0,9,-1,-2,0.5,0,0.2,0\n"
                                     "1,4,1.1,2,0.5,0.1,0,0\n");
  auto src = test::make("source.csv", yaml_params(file, "content: truth, frame: cartesian, position_unit: km, "
                                                        "vx_column: vx, vy_column: vy, vz_column: vz"));
  CHECK(src->produced_kinds() == mask(ItemKind::Truth));
  test::Collector out;
  out.attach_to(*src);
  test::drain(*src);
  REQUIRE(out.truths.size() == 3);
  CHECK(out.truths[1].target == 9);
  CHECK(out.truths[1].position.x() == -1000.0);
  CHECK(out.truths[1].velocity.y() == Approx(200.0));
  CHECK(out.truths[2].time == 1.0);
  CHECK(out.truths[2].position.x() == Approx(1100.0));
  // Refusals: a spherical truth log, half the velocity columns, a truth-only column elsewhere.
  CHECK_THAT(refusal(file, "content: truth"), Catch::Contains("frame: cartesian"));
  CHECK_THAT(refusal(file, "content: truth, frame: cartesian, vx_column: vx"), Catch::Contains("together"));
  CHECK_THAT(refusal(file, "frame: cartesian, target_column: target"), Catch::Contains("only to content: truth"));
  CHECK_THAT(refusal(file, "content: truth, frame: cartesian, target_column: id"), Catch::Contains("no column 'id'"));
}

// A 2-D radar's log (frame: polar): range and azimuth only, azimuth wrapped, range rate after them;
// a planar sensor's log (frame: planar): x and y. Their 3-D columns and parameters are refused.
TEST_CASE("polar and planar logs hold two position values") {
  TempDir dir;
  const std::string polar = dir.write("polar.csv", "time,range,azimuth,rdot\n0,12,350,-3\n1,12.1,10,-3\n");
  const auto ms = read_all(polar, "frame: polar, range_unit: km, range_rate_column: rdot, sigma_range: 30 m");
  REQUIRE(ms.size() == 2);
  CHECK(ms[0].frame == Frame::Polar);
  REQUIRE(ms[0].value.size() == 3);
  CHECK(ms[0].value[0] == Approx(12e3));
  CHECK(ms[0].value[1] == Approx(-10 * kDeg));
  CHECK(ms[0].value[2] == Approx(-3e3));  // km per second
  REQUIRE(ms[0].covariance.rows() == 3);
  CHECK(ms[0].covariance(0, 0) == Approx(900.0));
  CHECK(ms[0].has_range_rate);
  const std::string planar = dir.write("planar.csv", "time,x,y\n0,100,-200\n");
  const auto ps = read_all(planar, "frame: planar, sigma_position: 5 m");
  REQUIRE(ps.size() == 1);
  CHECK(ps[0].frame == Frame::Planar);
  REQUIRE(ps[0].value.size() == 2);
  CHECK(ps[0].value[1] == -200.0);
  REQUIRE(ps[0].covariance.rows() == 2);
  CHECK(ps[0].covariance(1, 1) == 25.0);
  CHECK_THAT(refusal(polar, "frame: polar, elevation_column: el"), Catch::Contains("no elevation"));
  CHECK_THAT(refusal(planar, "frame: planar, z_column: z"), Catch::Contains("no z"));
  CHECK_THAT(refusal(planar, "frame: planar, range_rate_column: rdot"), Catch::Contains("no range rate"));
  CHECK_THAT(refusal(planar, "frame: planar, sigma_range: 3 m"), Catch::Contains("spherical or polar"));
}
