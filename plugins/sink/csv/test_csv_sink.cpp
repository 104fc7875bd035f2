// Purpose: tests of sink.csv: header and rows, values against the inputs, empty cells, run order, measurement rows, paths, per-run rows sent between processes.
#include <trackflow/geometry.hpp>
#include <trackflow/host/guard.hpp>
#include <trackflow/output_path.hpp>
#include <trackflow/run_result_codec.hpp>

#include <Eigen/Dense>
#include <catch2/catch.hpp>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <functional>
#include <sstream>
#include <string>
#include <unistd.h>

#include "plugin_fixture.hpp"

using namespace trackflow;
namespace fs = std::filesystem;

namespace {

// kf carries the annotations of an adapter 'qs' (e.g. adapt.quality_switch); ekf none.
const InputInfo kKf{"kf", "filter.kalman", mask(ItemKind::Estimate), {"qs.grade_range", "qs.grade_azimuth", "qs.grade_elevation"}};
const InputInfo kEkf{"ekf", "filter.ekf", mask(ItemKind::Estimate)};
const InputInfo kTruth{"truth", "sim.trajectory", mask(ItemKind::Truth)};
const InputInfo kCm{"cm", "convert.classical", mask(ItemKind::Measurement)};

const std::string kHeader =
    "run,time_s,source,kind,updated,x_m,y_m,z_m,vx_m_per_s,vy_m_per_s,vz_m_per_s,sigma_x_m,sigma_y_m,sigma_z_m,"
    "sigma_vx_m_per_s,sigma_vy_m_per_s,sigma_vz_m_per_s,nis,nees,truth_x_m,truth_y_m,truth_z_m,truth_vx_m_per_s,"
    "truth_vy_m_per_s,truth_vz_m_per_s,qs.grade_range,qs.grade_azimuth,qs.grade_elevation";
enum Col { Run, Time, Source, Kind, Updated, X, Y, Z, VX, VY, VZ, SX, SY, SZ, SVX, SVY, SVZ, Nis, Nees, TX, TY, TZ, TVX, TVY, TVZ,
           QR, QAZ, QEL, Cells };

// A folder of this test process, removed when the process exits.
const fs::path& scratch_root() {
  struct Root {
    fs::path path = fs::temp_directory_path() / ("trackflow_test_sink_csv_" + std::to_string(::getpid()));
    ~Root() {
      std::error_code ec;
      fs::remove_all(path, ec);
    }
  };
  static const Root root;
  return root.path;
}

fs::path scratch(const std::string& name) {
  const fs::path p = scratch_root() / name;
  fs::remove_all(p);
  return p;
}

std::string slurp(const fs::path& p) {
  std::ifstream is(p, std::ios::binary);
  std::stringstream ss;
  ss << is.rdbuf();
  return ss.str();
}

std::vector<std::vector<std::string>> parse(const std::string& text) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream is(text);
  std::string line;
  while (std::getline(is, line)) {
    std::vector<std::string> cells;
    size_t start = 0;
    for (;;) {
      const size_t comma = line.find(',', start);
      cells.push_back(line.substr(start, comma - start));
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
    rows.push_back(cells);
  }
  return rows;
}

Truth truth(double t, Vec3 p, Vec3 v) {
  Truth x;
  x.time = t;
  x.position = p;
  x.velocity = v;
  return x;
}

Estimate estimate(double t, const Vec6& enu, const Mat6& cov, bool updated = true) {
  Estimate e;
  e.time = t;
  e.initialised = true;
  e.updated = updated;
  e.enu = enu;
  e.enu_covariance = cov;
  if (updated) {
    e.innovation.resize(3);
    e.innovation << 1, 2, 3;
    e.nis = 2.5 + t;
  }
  return e;
}

Mat6 covariance() {
  Mat6 P = Mat6::Zero();
  P.diagonal() << 4, 9, 16, 0.25, 1, 2.25;
  P(0, 1) = P(1, 0) = 1.5;
  return P;
}

// One run: truth on port 2, filter kf on port 0, filter ekf on port 1; two steps, the second
// with its truth delivered after the estimates when `truth_last` is set.
void feed(Component& c, std::uint64_t run, bool truth_last = false) {
  for (int k = 0; k < 2; ++k) {
    const double t = 0.5 * k;
    const Truth tr = truth(t, Vec3(1000 + 10.0 * run, 2000 + k, 300), Vec3(-100, 50, 0));
    Vec6 x;
    x << tr.position, tr.velocity;
    if (!truth_last) c.on_truth(tr, 2);
    c.on_estimate(estimate(t, x + Vec6::Constant(1.0), covariance()), 0);
    c.on_estimate(estimate(t, x + Vec6::Constant(-2.0), covariance(), k == 0), 1);
    if (truth_last) c.on_truth(tr, 2);
  }
}

std::shared_ptr<Component> make_csv(const std::string& params, const std::vector<InputInfo>& inputs = {kKf, kEkf, kTruth}) {
  auto c = test::make("sink.csv", params, "log");
  c->set_inputs(inputs);
  return c;
}

// Runs `runs` runs, run r on worker `assign(r)`, in the order `order`; merges in run order.
std::string ensemble_file(const fs::path& dir, const std::vector<std::uint64_t>& order, int workers,
                          const std::function<int(std::uint64_t)>& assign, bool truth_last = false) {
  std::vector<std::shared_ptr<Component>> pool;
  for (int w = 0; w < workers; ++w) pool.push_back(make_csv("{}"));
  auto aggregate = make_csv("{}");
  std::vector<std::unique_ptr<RunResult>> results(order.size());
  Diagnostics diag;
  for (std::uint64_t r : order) {
    Component& c = *pool[static_cast<size_t>(assign(r))];
    c.start_run({r, 99, &diag});
    feed(c, r, truth_last);
    results[r] = c.end_run();
  }
  for (auto& r : results) aggregate->merge(*r);
  Summary s;
  aggregate->finish(s, {"log", dir.string(), order.size()});
  REQUIRE(s.files.size() == 1);
  CHECK(s.files[0] == (dir / "log.csv").string());
  return slurp(dir / "log.csv");
}

double num(const std::string& cell) { return std::stod(cell); }

// Ends the one run of `c`, merges it, finishes the file in `dir` and returns its rows (the header first).
std::vector<std::vector<std::string>> finished_rows(Component& c, const fs::path& dir) {
  auto result = c.end_run();
  c.merge(*result);
  Summary s;
  c.finish(s, {"log", dir.string(), 1});
  return parse(slurp(dir / "log.csv"));
}

}  // namespace

// the file has the header, one row per estimate and run, 28 cells each, no nan
TEST_CASE("the file has the header and one full row per estimate") {
  const fs::path dir = scratch("basic") / "nested";  // --out need not exist yet
  const std::string text = ensemble_file(dir, {0, 1, 2}, 1, [](std::uint64_t) { return 0; });
  const auto rows = parse(text);
  REQUIRE(rows.size() == 1 + 3 * 4);
  CHECK(text.substr(0, text.find('\n')) == kHeader);
  for (const auto& r : rows) CHECK(r.size() == Cells);
  CHECK(text.find("nan") == std::string::npos);
  CHECK(text.find("inf") == std::string::npos);
  // Run column, then arrival order within a run.
  CHECK(rows[1][Run] == "0");
  CHECK(rows[5][Run] == "1");
  CHECK(rows[12][Run] == "2");
  CHECK(rows[1][Source] == "kf");
  CHECK(rows[2][Source] == "ekf");
  CHECK(rows[1][Kind] == "estimate");
}

// cells hold the estimate, its sigmas, NIS, NEES and the matching truth
TEST_CASE("cells hold the estimate/sigmas/NIS/NEES/truth") {
  const fs::path dir = scratch("values");
  const auto rows = parse(ensemble_file(dir, {0, 1}, 1, [](std::uint64_t) { return 0; }));
  // Run 1, step 1, filter kf: truth (1010, 2001, 300, -100, 50, 0), error +1 everywhere.
  const auto& r = rows[7];
  REQUIRE(r[Run] == "1");
  CHECK(num(r[Time]) == 0.5);
  CHECK(r[Updated] == "1");
  CHECK(num(r[X]) == Approx(1011));
  CHECK(num(r[Y]) == Approx(2002));
  CHECK(num(r[VZ]) == Approx(1));
  CHECK(num(r[SX]) == Approx(2));
  CHECK(num(r[SY]) == Approx(3));
  CHECK(num(r[SVZ]) == Approx(1.5));
  CHECK(num(r[Nis]) == Approx(3.0));
  const Vec6 e = Vec6::Constant(1.0);
  CHECK(num(r[Nees]) == Approx(e.dot(covariance().inverse() * e)).epsilon(1e-8));
  CHECK(num(r[TX]) == Approx(1010));
  CHECK(num(r[TY]) == Approx(2001));
  CHECK(num(r[TVX]) == Approx(-100));
  // The ekf's coasting step: updated 0 and an empty NIS cell.
  const auto& coast = rows[8];
  REQUIRE(coast[Source] == "ekf");
  CHECK(coast[Updated] == "0");
  CHECK(coast[Nis].empty());
  CHECK(!coast[Nees].empty());
}

// cells without a value are empty: no truth at that time, non-positive covariance
TEST_CASE("cells without a value are empty") {
  const fs::path dir = scratch("empty");
  auto c = make_csv("{}");
  Diagnostics diag;
  c->start_run({0, 1, &diag});
  c->on_truth(truth(0.0, Vec3(1, 2, 3), Vec3::Zero()), 2);
  Mat6 bad = Mat6::Identity();
  bad(2, 2) = -1.0;  // sigma_z undefined, NEES undefined
  c->on_estimate(estimate(0.0, Vec6::Zero(), bad), 0);
  c->on_estimate(estimate(0.3, Vec6::Zero(), Mat6::Identity()), 0);  // no truth sample at 0.3
  Estimate early = estimate(0.4, Vec6::Zero(), Mat6::Identity());
  early.initialised = false;  // not written
  c->on_estimate(early, 0);
  c->on_truth(truth(1.0, Vec3(1, 2, 3), Vec3::Zero()), 2);
  auto result = c->end_run();
  c->merge(*result);
  Summary s;
  c->finish(s, {"log", dir.string(), 1});
  const std::string text = slurp(dir / "log.csv");
  CHECK(text.find("nan") == std::string::npos);
  const auto rows = parse(text);
  REQUIRE(rows.size() == 3);
  CHECK(rows[1][SZ].empty());
  CHECK(num(rows[1][SX]) == 1.0);
  CHECK(rows[1][Nees].empty());
  CHECK(num(rows[1][TZ]) == 3.0);
  for (int col : {Nees, TX, TY, TZ, TVX, TVY, TVZ}) CHECK(rows[2][col].empty());
  CHECK(!rows[2][Nis].empty());
  CHECK(s.find("rows")->value == 2);
}

TEST_CASE("annotation columns carry adapter values or stay empty") {
  const fs::path dir = scratch("quality");
  auto c = make_csv("{}");
  Diagnostics diag;
  c->start_run({0, 1, &diag});
  c->on_truth(truth(0.0, Vec3(1, 2, 3), Vec3::Zero()), 2);
  Estimate graded = estimate(0.0, Vec6::Zero(), Mat6::Identity());
  graded.annotation_count = 3;
  graded.annotations[0] = 0;
  graded.annotations[1] = 2;
  graded.annotations[2] = std::numeric_limits<double>::quiet_NaN();  // not graded yet
  c->on_estimate(graded, 0);
  c->on_estimate(estimate(0.0, Vec6::Zero(), Mat6::Identity()), 1);  // no adapter: empty everywhere
  auto result = c->end_run();
  c->merge(*result);
  Summary s;
  c->finish(s, {"log", dir.string(), 1});
  const auto rows = parse(slurp(dir / "log.csv"));
  REQUIRE(rows.size() == 3);
  CHECK(rows[1][QR] == "0");
  CHECK(rows[1][QAZ] == "2");
  CHECK(rows[1][QEL].empty());
  for (int col : {QR, QAZ, QEL}) CHECK(rows[2][col].empty());
}

// the file is byte-identical whatever the worker assignment, run order and item order within a step
TEST_CASE("the file is byte-identical whatever the order") {
  const std::string serial = ensemble_file(scratch("serial"), {0, 1, 2, 3}, 1, [](std::uint64_t) { return 0; });
  const std::string interleaved = ensemble_file(scratch("two"), {0, 1, 2, 3}, 2, [](std::uint64_t r) { return int(r % 2); });
  const std::string reversed = ensemble_file(scratch("rev"), {3, 1, 2, 0}, 3, [](std::uint64_t r) { return int(r % 3); });
  const std::string truth_last = ensemble_file(scratch("late"), {0, 1, 2, 3}, 1, [](std::uint64_t) { return 0; }, true);
  CHECK(parse(serial).size() == 1 + 4 * 4);
  CHECK(interleaved == serial);
  CHECK(reversed == serial);
  CHECK(truth_last == serial);
}

// measurement rows: Cartesian position, sigmas when Cartesian, truth, no filter columns
TEST_CASE("measurement rows have position sigmas and truth") {
  const fs::path dir = scratch("meas");
  auto c = make_csv("{ include_measurements: true, precision: 12 }", {kKf, kTruth, kCm});
  Diagnostics diag;
  c->start_run({0, 1, &diag});
  const Vec3 p(3000, 4000, 500);
  c->on_truth(truth(0.0, p, Vec3(1, 2, 3)), 1);
  Measurement cart;
  cart.frame = Frame::Cartesian;
  cart.value.resize(4);  // with range rate: only x, y, z are a position
  cart.value << 3001, 4002, 503, -7;
  cart.covariance = MeasCov::Zero(4, 4);
  cart.covariance.diagonal() << 4, 9, 16, 1;
  c->on_measurement(cart, 2);
  Measurement sph;
  sph.frame = Frame::Spherical;
  sph.azimuth = AzimuthConvention::XCounterClockwise;
  sph.sensor_position = Vec3(100, 200, 0);
  const Vec3 d = p - sph.sensor_position;
  sph.value.resize(3);
  sph.value << d.norm(), std::atan2(d.y(), d.x()), std::asin(d.z() / d.norm());
  sph.covariance = MeasCov::Identity(3, 3);
  c->on_measurement(sph, 2);
  Measurement invalid = cart;
  invalid.valid = false;
  c->on_measurement(invalid, 2);
  auto result = c->end_run();
  c->merge(*result);
  Summary s;
  c->finish(s, {"log", dir.string(), 1});
  const auto rows = parse(slurp(dir / "log.csv"));
  REQUIRE(rows.size() == 3);
  const auto& a = rows[1];
  CHECK(a[Source] == "cm");
  CHECK(a[Kind] == "measurement");
  CHECK(a[Updated].empty());
  CHECK(num(a[X]) == 3001);
  CHECK(num(a[Z]) == 503);
  CHECK(num(a[SX]) == 2);
  CHECK(num(a[SZ]) == 4);
  for (int col : {VX, VY, VZ, SVX, SVY, SVZ, Nis, Nees, QR, QAZ, QEL}) CHECK(a[col].empty());
  CHECK(num(a[TX]) == 3000);
  CHECK(num(a[TVZ]) == 3);
  const auto& b = rows[2];
  CHECK(num(b[X]) == Approx(3000).margin(1e-6));
  CHECK(num(b[Y]) == Approx(4000).margin(1e-6));
  CHECK(num(b[Z]) == Approx(500).margin(1e-6));
  CHECK(b[SX].empty());

  // Off by default.
  auto quiet = make_csv("{}", {kKf, kTruth, kCm});
  quiet->start_run({0, 1, &diag});
  quiet->on_measurement(cart, 2);
  auto none = quiet->end_run();
  quiet->merge(*none);
  Summary s2;
  quiet->finish(s2, {"log", (dir / "quiet").string(), 1});
  CHECK(parse(slurp(dir / "quiet" / "log.csv")).size() == 1);
  CHECK(s2.find("rows")->value == 0);
}

// path is relative to the output folder; precision sets significant digits
TEST_CASE("relative path and precision") {
  const fs::path dir = scratch("path");
  auto c = make_csv("{ path: sub/run.csv, precision: 4 }", {kKf});
  Diagnostics diag;
  c->start_run({0, 1, &diag});
  c->on_estimate(estimate(3.14159265, Vec6::Constant(123456.789), Mat6::Identity()), 0);
  auto result = c->end_run();
  c->merge(*result);
  Summary s;
  c->finish(s, {"log", dir.string(), 1});
  REQUIRE(s.files.size() == 1);
  CHECK(s.files[0] == (dir / "sub" / "run.csv").string());
  const auto rows = parse(slurp(dir / "sub" / "run.csv"));
  REQUIRE(rows.size() == 2);
  CHECK(rows[1][Time] == "3.142");
  CHECK(rows[1][X] == "1.235e+05");
  CHECK(rows[1][TX].empty());
  CHECK_THROWS_AS(test::make("sink.csv", "{ precision: 0 }"), ConfigError);
}

// without precision every number is the shortest text that reads back as exactly the same
// double: lossless, the form of std::to_chars (e.g. 0.1, 1e-05, -0, 1.7976931348623157e+308)
TEST_CASE("numbers are shortest round-trip by default") {
  const fs::path dir = scratch("shortest");
  auto c = make_csv("{}", {kKf, kTruth});
  Diagnostics diag;
  c->start_run({0, 1, &diag});
  std::mt19937_64 gen(11);
  std::vector<Vec6> written;
  const double awkward[] = {0.1, 1e-05, -0.0, 1e20, 5e-324, 2.2250738585072014e-308, 1.7976931348623157e308,
                            -123456.78901234567, 6123.456789012345, 100, 1.5, 0.30000000000000004};
  for (int k = 0; k < 200; ++k) {
    Vec6 x;
    for (int i = 0; i < 6; ++i) {
      if (k < 2) {
        x(i) = awkward[(6 * k + i) % std::size(awkward)];
        continue;
      }
      std::uint64_t bits = gen();
      std::memcpy(&x(i), &bits, sizeof bits);
      if (!std::isfinite(x(i))) x(i) = 1.0 / (k + i + 1);
    }
    written.push_back(x);
    c->on_estimate(estimate(0.1 * k, x, Mat6::Identity()), 0);
  }
  const auto rows = finished_rows(*c, dir);
  REQUIRE(rows.size() == 201);
  CHECK(rows[1][X] == "0.1");
  CHECK(rows[1][Y] == "1e-05");
  CHECK(rows[1][Z] == "-0");
  CHECK(rows[1][VX] == "1e+20");
  CHECK(rows[1][VY] == "5e-324");
  CHECK(rows[2][X] == "1.7976931348623157e+308");
  CHECK(rows[2][Z] == "6123.456789012345");
  CHECK(rows[2][VX] == "100");
  CHECK(rows[3][Time] == "0.2");
  CHECK(rows[4][Time] == "0.30000000000000004");  // 0.1 * 3
  for (std::size_t k = 0; k < written.size(); ++k)
    for (int i = 0; i < 6; ++i) {
      const std::string& cell = rows[k + 1][X + i];
      const double back = std::strtod(cell.c_str(), nullptr);
      if (std::memcmp(&back, &written[k](i), sizeof back) != 0) FAIL("row " << k << ": " << cell << " does not read back");
      char longest[32];
      std::snprintf(longest, sizeof longest, "%.17g", written[k](i));
      CHECK(cell.size() <= std::strlen(longest));
    }
}

// The temporaries of log.csv in `dir` (safe_output.hpp: .log.csv.<pid>.<random>.partial).
static int partials(const fs::path& dir) {
  int n = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name.rfind(".log.csv.", 0) == 0 && name.size() > 8 && name.substr(name.size() - 8) == ".partial") ++n;
  }
  return n;
}

// with an output folder known (as in the engine) rows are streamed at merge time, in run order
TEST_CASE("rows stream into a partial file renamed at the end") {
  const std::string reference = ensemble_file(scratch("stream_ref"), {0, 1, 2}, 1, [](std::uint64_t) { return 0; });
  const fs::path dir = scratch("stream");
  const std::string out = dir.string();
  host::OutputDirectoryScope scope(out);
  auto worker = make_csv("{}");
  auto aggregate = make_csv("{}");
  Diagnostics diag;
  for (std::uint64_t r = 0; r < 3; ++r) {
    worker->start_run({r, 1, &diag});
    feed(*worker, r);
    auto result = worker->end_run();
    aggregate->merge(*result);
    // Written as the runs are merged, under a name that is not the final one.
    CHECK(partials(dir) == 1);
    CHECK_FALSE(fs::exists(dir / "log.csv"));
  }
  Summary s;
  aggregate->finish(s, {"log", out, 3});
  CHECK(partials(dir) == 0);
  // Byte-identical to the file written all at once without an output folder.
  CHECK(slurp(dir / "log.csv") == reference);
}

// a sink that is destroyed before finish (a failed ensemble) leaves no file behind
TEST_CASE("an unfinished ensemble leaves no file") {
  const fs::path dir = scratch("unfinished");
  const std::string out = dir.string();
  {
    host::OutputDirectoryScope scope(out);
    auto worker = make_csv("{}");
    auto aggregate = make_csv("{}");
    Diagnostics diag;
    worker->start_run({0, 1, &diag});
    feed(*worker, 0);
    auto result = worker->end_run();
    aggregate->merge(*result);
    CHECK(partials(dir) == 1);
  }
  CHECK(partials(dir) == 0);
  CHECK_FALSE(fs::exists(dir / "log.csv"));
}

// a NaN is written as nan (not as an empty, missing cell) and fails the run
TEST_CASE("a NaN value is written as nan and fails the run") {
  const fs::path dir = scratch("nan");
  auto c = make_csv("{}", {kKf, kTruth});
  Diagnostics diag;
  c->start_run({0, 1, &diag});
  c->on_truth(truth(0.0, Vec3(1, 2, 3), Vec3::Zero()), 1);
  Vec6 x = Vec6::Zero();
  x(1) = std::numeric_limits<double>::quiet_NaN();
  c->on_estimate(estimate(0.0, x, Mat6::Identity()), 0);
  c->on_truth(truth(1.0, Vec3(1, 2, 3), Vec3::Zero()), 1);
  auto result = c->end_run();
  c->merge(*result);
  Summary s;
  try {
    c->finish(s, {"log", dir.string(), 1});
    FAIL("a NaN in the file must fail the run");
  } catch (const DataError& e) {
    CHECK_THAT(e.what(), Catch::Matchers::Contains("non-finite value(s) (nan/inf)"));
    CHECK_THAT(e.what(), Catch::Matchers::Contains("the first in run 0, t=0 s, column y"));
  }
  const auto rows = parse(slurp(dir / "log.csv"));
  REQUIRE(rows.size() == 2);
  CHECK(rows[1][Y] == "nan");
  CHECK(rows[1][Nees] == "nan");  // computed from the NaN: a NaN too, not a missing value
}

// a path outside --out is refused when the node is built, unless the user allowed it
TEST_CASE("paths outside the output folder are refused") {
  allow_output_outside(false);
  CHECK_THROWS_WITH(test::make("sink.csv", "{ path: /tmp/x.csv }"), Catch::Matchers::Contains("absolute path"));
  CHECK_THROWS_WITH(test::make("sink.csv", "{ path: ../x.csv }"), Catch::Matchers::Contains("leaves the output folder"));
  allow_output_outside(true);
  CHECK_NOTHROW(test::make("sink.csv", "{ path: /tmp/x.csv }"));
  allow_output_outside(false);
}

namespace {

// Temporary files of sink 'log' this process holds open in `dir` (they are unlinked at once, so
// only /proc/self/fd still names them).
int temp_files_in(const fs::path& dir) {
  int n = 0;
  const std::string prefix = (dir / ".log.run-").string();
  for (const auto& e : fs::directory_iterator("/proc/self/fd")) {
    std::error_code ec;
    const fs::path target = fs::read_symlink(e.path(), ec);
    if (!ec && target.string().rfind(prefix, 0) == 0) ++n;
  }
  return n;
}

// A run of `steps` steps (large enough to outgrow memory: 20 000 steps are ~6 MB of rows at ~160 bytes a row).
void feed_long(Component& c, std::uint64_t run, int steps) {
  for (int k = 0; k < steps; ++k) {
    const double t = 0.1 * k;
    const Truth tr = truth(t, Vec3(1000 + run, 2000 + 0.1 * k, 300), Vec3(-100, 50, 0));
    Vec6 x;
    x << tr.position, tr.velocity;
    c.on_truth(tr, 2);
    c.on_estimate(estimate(t, x + Vec6::Constant(1.0 / 3.0), covariance()), 0);
    c.on_estimate(estimate(t, x - Vec6::Constant(2.0 / 7.0), covariance(), k % 2 == 0), 1);
  }
}

}  // namespace

// under mpirun a run's rows are sent as bytes (RunResultCodec) and merged on another instance:
// the file is byte-identical to merging the runs where they ran, and a large run, spilled to a
// temporary file where it ran, is spilled again where it is received instead of held in memory
TEST_CASE("rows sent between processes give the same file") {
  const fs::path root = scratch("codec");
  const std::string work = (root / "work").string(), a = (root / "direct").string(), b = (root / "decoded").string();
  auto worker = make_csv("{}");
  auto direct = make_csv("{}");
  auto decoded = make_csv("{}");
  const auto& codec = dynamic_cast<const RunResultCodec&>(*worker);
  Diagnostics diag;
  std::size_t largest = 0;
  for (std::uint64_t r = 0; r < 3; ++r) {
    std::unique_ptr<RunResult> result;
    {
      host::OutputDirectoryScope scope(work);
      worker->start_run({r, 1, &diag});
      if (r == 1)
        feed_long(*worker, r, 20000);
      else
        feed(*worker, r);
      result = worker->end_run();
      // The long run went to a temporary file where it ran.
      CHECK(temp_files_in(root / "work") == (r == 1 ? 1 : 0));
    }
    std::string bytes;
    ByteWriter w(bytes);
    codec.save_run_result(*result, w);
    largest = std::max(largest, bytes.size());
    std::unique_ptr<RunResult> loaded;
    {
      host::OutputDirectoryScope scope(b);
      ByteReader in(bytes.data(), bytes.size());
      loaded = dynamic_cast<const RunResultCodec&>(*decoded).load_run_result(in);
      CHECK(in.done());
      // Received, the long run is kept in a temporary file again, not in memory.
      CHECK(temp_files_in(root / "decoded") == (r == 1 ? 1 : 0));
      // A truncated message is an error, not a short file.
      ByteReader cut(bytes.data(), bytes.size() - 1);
      CHECK_THROWS_AS(codec.load_run_result(cut), DataError);
    }
    {
      host::OutputDirectoryScope scope(a);
      direct->merge(*result);
    }
    {
      host::OutputDirectoryScope scope(b);
      decoded->merge(*loaded);
    }
  }
  CHECK(largest > (std::size_t{4} << 20));
  Summary sa, sb;
  direct->finish(sa, {"log", a, 3});
  decoded->finish(sb, {"log", b, 3});
  REQUIRE(sa.metrics.size() == sb.metrics.size());
  CHECK(sa.metrics[0].value == sb.metrics[0].value);  // rows
  CHECK(sa.metrics[0].value == 2 * 2 + 2 * 20000 + 2 * 2);
  const std::string file = slurp(fs::path(a) / "log.csv");
  CHECK(file.size() > (std::size_t{4} << 20));
  CHECK(slurp(fs::path(b) / "log.csv") == file);
}

// the first non-finite value's place and the count travel with the rows
TEST_CASE("a NaN in a run sent between processes still fails the run") {
  const fs::path dir = scratch("codec_nan");
  auto worker = make_csv("{}", {kKf, kTruth});
  auto aggregate = make_csv("{}", {kKf, kTruth});
  Diagnostics diag;
  worker->start_run({4, 1, &diag});
  Vec6 x = Vec6::Zero();
  x(2) = std::numeric_limits<double>::infinity();
  worker->on_estimate(estimate(0.5, x, Mat6::Identity()), 0);
  auto result = worker->end_run();
  std::string bytes;
  ByteWriter w(bytes);
  dynamic_cast<const RunResultCodec&>(*worker).save_run_result(*result, w);
  ByteReader in(bytes.data(), bytes.size());
  auto loaded = dynamic_cast<const RunResultCodec&>(*aggregate).load_run_result(in);
  aggregate->merge(*loaded);
  Summary s;
  CHECK_THROWS_WITH(aggregate->finish(s, {"log", dir.string(), 1}),
                    Catch::Matchers::Contains("the first in run 4, t=0.5 s, column z"));
}

// A tracker's track sets: one row per track, kind track, with its id and status; truth by target only.
TEST_CASE("track sets: a row per track, id, status, own target truth") {
  const InputInfo tracker{"mtt", "tracker.multi", mask(ItemKind::Tracks)};
  const InputInfo scenario{"scenario", "sim.scenario", mask(ItemKind::Truth)};
  auto c = make_csv("{}", {tracker, scenario});
  c->start_run({0, 1, nullptr});
  Truth a = truth(1.0, Vec3(10, 20, 0), Vec3(1, 0, 0));
  a.target = 0;
  Truth b = truth(1.0, Vec3(500, 0, 0), Vec3(0, 1, 0));
  b.target = 1;
  c->on_truth(a, 1);
  c->on_truth(b, 1);
  std::vector<TrackEstimate> set(3);
  Vec6 x;
  x << 11, 20, 0, 1, 0, 0;
  set[0].id = 4;
  set[0].status = TrackStatus::Confirmed;
  set[0].estimate = estimate(1.0, x, covariance());
  set[0].estimate.target = 0;
  set[1].id = 9;
  set[1].status = TrackStatus::Tentative;
  set[1].estimate = estimate(1.0, x * 2.0, covariance(), false);
  set[1].estimate.target = kOriginUnknown;  // from clutter: no truth, even with truth at that time
  set[2].id = 11;
  set[2].status = TrackStatus::Deleted;
  set[2].estimate.initialised = false;  // nothing to write
  c->on_tracks(TrackSet{1.0, set}, 0);
  const auto rows = finished_rows(*c, scratch("tracks"));
  REQUIRE(rows.size() == 3);
  const std::vector<std::string>& head = rows[0];
  REQUIRE(head.size() == 27);
  CHECK(head[25] == "track_id");
  CHECK(head[26] == "track_status");
  CHECK(rows[1][Kind] == "track");
  CHECK(rows[1][Source] == "mtt");
  CHECK(rows[1][25] == "4");
  CHECK(rows[1][26] == "confirmed");
  CHECK(num(rows[1][TX]) == 10.0);  // target 0's truth
  CHECK(!rows[1][Nees].empty());
  CHECK(rows[2][25] == "9");
  CHECK(rows[2][26] == "tentative");
  CHECK(rows[2][TX].empty());  // unknown origin: no truth is claimed
  CHECK(rows[2][Nees].empty());
}

// A tracker's per-track adapters (tracker.multi `adapters:`): the values on each track's estimate
// go to the columns its input names, per track; a track without values leaves them empty.
TEST_CASE("track sets: per-track adapter annotations as columns") {
  InputInfo tracker{"mtt", "tracker.multi", mask(ItemKind::Tracks)};
  tracker.annotations = {"mtt.adapt.innovation_r.sigma_x", "mtt.adapt.innovation_r.sigma_y"};
  auto c = make_csv("{}", {tracker});
  c->start_run({0, 1, nullptr});
  std::vector<TrackEstimate> set(2);
  Vec6 x;
  x << 11, 20, 0, 1, 0, 0;
  for (int i = 0; i < 2; ++i) {
    set[static_cast<size_t>(i)].id = static_cast<std::uint64_t>(i + 1);
    set[static_cast<size_t>(i)].estimate = estimate(1.0, x, covariance());
  }
  set[0].estimate.annotation_count = 2;
  set[0].estimate.annotations[0] = 2.5;
  set[0].estimate.annotations[1] = 7.25;
  c->on_tracks(TrackSet{1.0, set}, 0);
  const auto rows = finished_rows(*c, scratch("track_annotations"));
  REQUIRE(rows.size() == 3);
  const std::vector<std::string>& head = rows[0];
  REQUIRE(head.size() >= 2);
  CHECK(head[head.size() - 2] == "mtt.adapt.innovation_r.sigma_x");
  CHECK(head.back() == "mtt.adapt.innovation_r.sigma_y");
  CHECK(num(rows[1][head.size() - 2]) == 2.5);
  CHECK(num(rows[1].back()) == 7.25);
  CHECK(rows[2][head.size() - 2].empty());
  CHECK(rows[2].back().empty());
}

// A scan: one row per detection, kind detection, its position, its origin column, and the truth of
// its origin target only (clutter has none).
TEST_CASE("scans: a row per detection with origin and target truth") {
  const InputInfo radar{"scenario", "sim.scenario", mask(ItemKind::Scan)};
  const InputInfo scenario{"scenario", "sim.scenario", mask(ItemKind::Truth)};
  auto c = make_csv("{include_detections: true}", {radar, scenario});
  c->start_run({0, 1, nullptr});
  Truth a = truth(2.0, Vec3(10, 20, 0), Vec3(1, 0, 0));
  a.target = 3;
  c->on_truth(a, 1);
  std::vector<Detection> d(2);
  for (auto& x : d) {
    x.value.resize(3);
    x.covariance = MeasCov::Identity(3, 3) * 4.0;
  }
  d[0].value << 11, 19, 0;
  d[0].origin = 3;
  d[1].value << -50, 70, 1;
  d[1].origin = kOriginClutter;
  Scan s;
  s.time = 2.0;
  s.sensor.frame = Frame::Cartesian;
  s.detections = d;
  c->on_scan(s, 0);
  const auto rows = finished_rows(*c, scratch("scans"));
  REQUIRE(rows.size() == 3);
  REQUIRE(rows[0].size() == 26);
  CHECK(rows[0][25] == "origin");
  CHECK(rows[1][Kind] == "detection");
  CHECK(num(rows[1][X]) == 11.0);
  CHECK(num(rows[1][TX]) == 10.0);
  CHECK(rows[1][25] == "3");
  CHECK(rows[1][Nees].empty());
  CHECK(rows[2][25] == "clutter");
  CHECK(rows[2][TX].empty());
  // Off by default: a scenario wired for its truth also delivers its scans, which then write nothing.
  auto plain = make_csv("{}", {radar, scenario});
  plain->start_run({0, 1, nullptr});
  plain->on_truth(a, 1);
  plain->on_scan(s, 0);
  const auto none = finished_rows(*plain, scratch("scans_off"));
  REQUIRE(none.size() == 1);
  CHECK(none[0].size() == 25);
}
