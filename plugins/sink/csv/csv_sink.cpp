// Purpose: sink.csv — one CSV file of all runs: estimates of any number of filters, optional measurements, matching truth and NEES.
#include "csv_row.hpp"

#include <trackflow/geometry.hpp>
#include <trackflow/plugin.hpp>

#include <Eigen/Cholesky>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

namespace trackflow {
namespace {

constexpr const char* kHeader =
    "run,time,source,kind,updated,x,y,z,vx,vy,vz,sigma_x,sigma_y,sigma_z,sigma_vx,sigma_vy,sigma_vz,nis,nees,"
    "truth_x,truth_y,truth_z,truth_vx,truth_vy,truth_vz";

// Opt-in (full_covariance): the upper triangle of the ENU covariance, row by row; units m2,
// m2/s and m2/s2 (the sigma_* columns are the square roots of its diagonal).
constexpr const char* kCovarianceHeader =
    ",cov_x_x,cov_x_y,cov_x_z,cov_x_vx,cov_x_vy,cov_x_vz,cov_y_y,cov_y_z,cov_y_vx,cov_y_vy,cov_y_vz,cov_z_z,cov_z_vx,"
    "cov_z_vy,cov_z_vz,cov_vx_vx,cov_vx_vy,cov_vx_vz,cov_vy_vy,cov_vy_vz,cov_vz_vz";

// Truth samples within this of an item's time are its truth (the same default as sink.metrics).
constexpr double kTimeTolerance = 1e-6;

struct CsvRunResult final : RunResult {
  std::string rows;
  std::uint64_t count = 0;
};

// An item waiting for the truth of its time step, which may arrive after it.
struct PendingRow {
  double time = 0.0;
  int port = 0;
  std::uint32_t target = 0;
  bool measurement = false;
  bool updated = false;
  bool has_velocity = false;
  bool has_sigma = false;
  double nis = 0.0;
  Vec6 value = Vec6::Zero();
  Vec6 sigma = Vec6::Zero();
  Mat6 covariance = Mat6::Zero();  // estimates: for NEES
  double annotations[kMaxAnnotations] = {};  // estimates: their filter's adapter annotations
  int annotation_count = 0;
};

class CsvSink final : public Component {
 public:
  explicit CsvSink(const Params& p)
      : path_(p.has("path") ? p.text("path") : std::string()),
        path_where_(p.where("path")),
        include_measurements_(p.boolean("include_measurements")),
        full_covariance_(p.boolean("full_covariance")),
        precision_(static_cast<int>(p.integer("precision"))) {
    if (p.has("path") && path_.empty()) throw p.error("path", "must not be empty (leave it out for '<node id>.csv')");
    truth_.reserve(4096);
    pending_.reserve(1024);
    rows_.reserve(std::size_t{1} << 20);
  }

  void set_inputs(const std::vector<InputInfo>& inputs) override {
    sources_.clear();
    annotation_columns_.clear();
    column_of_.clear();
    truth_input_ = false;
    for (const auto& in : inputs) {
      sources_.push_back(csv::quoted(in.node));
      truth_input_ |= (in.kinds & mask(ItemKind::Truth)) != 0;
      // One column per annotation that exists in the pipeline ("<adapter id>.<name>"), shared
      // by inputs that carry the same name.
      auto& columns = column_of_.emplace_back();
      for (const auto& name : in.annotations) {
        auto it = std::find(annotation_columns_.begin(), annotation_columns_.end(), name);
        if (it == annotation_columns_.end()) it = annotation_columns_.insert(annotation_columns_.end(), name);
        columns.push_back(static_cast<int>(it - annotation_columns_.begin()));
      }
    }
    row_annotations_.assign(annotation_columns_.size(), 0.0);
  }

  void start_run(const RunContext& ctx) override {
    run_ = ctx.run;
    truth_.clear();
    pending_.clear();
    rows_.clear();
    row_count_ = 0;
    latest_truth_ = -std::numeric_limits<double>::infinity();
  }

  void on_truth(const Truth& t, int) override {
    if (truth_.empty() || truth_.back().time <= t.time)
      truth_.push_back(t);
    else
      truth_.insert(std::upper_bound(truth_.begin(), truth_.end(), t,
                                     [](const Truth& a, const Truth& b) { return a.time < b.time; }),
                    t);
    latest_truth_ = std::max(latest_truth_, t.time);
    flush(false);
  }

  void on_estimate(const Estimate& e, int port) override {
    if (!e.initialised) return;
    PendingRow& r = pending_.emplace_back();
    r.time = e.time;
    r.port = port;
    r.target = e.target;
    r.updated = e.updated;
    r.nis = e.updated && e.innovation.size() > 0 ? e.nis : std::numeric_limits<double>::quiet_NaN();
    r.value = e.enu;
    r.has_velocity = true;
    r.has_sigma = true;
    for (int i = 0; i < 6; ++i) r.sigma(i) = e.enu_covariance(i, i) >= 0.0 ? std::sqrt(e.enu_covariance(i, i)) : NAN;
    r.covariance = e.enu_covariance;
    r.annotation_count = e.annotation_count;
    for (int i = 0; i < e.annotation_count; ++i) r.annotations[i] = e.annotations[i];
    flush(false);
  }

  void on_measurement(const Measurement& m, int port) override {
    if (!include_measurements_ || !m.valid || m.value.size() < 3) return;
    PendingRow& r = pending_.emplace_back();
    r.time = m.time;
    r.port = port;
    r.measurement = true;
    if (m.frame == Frame::Cartesian) {
      r.value.head<3>() = m.value.head<3>();
      r.has_sigma = m.covariance.rows() >= 3 && m.covariance.cols() >= 3;
      for (int i = 0; i < 3 && r.has_sigma; ++i)
        r.sigma(i) = m.covariance(i, i) >= 0.0 ? std::sqrt(m.covariance(i, i)) : NAN;
      if (r.has_sigma) r.covariance.topLeftCorner<3, 3>() = m.covariance.topLeftCorner(3, 3);
    } else {
      r.value.head<3>() = spherical_to_enu(m.value(0), m.value(1), m.value(2), m.azimuth) + m.sensor_position;
    }
    flush(false);
  }

  std::unique_ptr<RunResult> end_run() override {
    flush(true);
    auto r = std::make_unique<CsvRunResult>();
    r->rows = rows_;
    r->count = row_count_;
    return r;
  }

  void merge(RunResult& result) override {
    auto& r = static_cast<CsvRunResult&>(result);
    file_ += r.rows;
    total_rows_ += r.count;
  }

  void finish(Summary& summary, const FinishContext& ctx) override {
    namespace fs = std::filesystem;
    const fs::path file = fs::path(ctx.output_dir.empty() ? "." : ctx.output_dir) /
                          (path_.empty() ? ctx.node + ".csv" : path_);
    std::error_code ec;
    if (file.has_parent_path()) fs::create_directories(file.parent_path(), ec);
    if (ec) throw ConfigError("cannot create the folder '" + file.parent_path().string() + "': " + ec.message(), path_where_, ctx.node);
    std::ofstream os(file, std::ios::binary | std::ios::trunc);
    if (os) {
      os << kHeader;
      if (full_covariance_) os << kCovarianceHeader;
      for (const auto& name : annotation_columns_) os << ',' << csv::quoted(name);
      os << '\n';
      os.write(file_.data(), static_cast<std::streamsize>(file_.size()));
      os.flush();
    }
    if (!os)
      throw ConfigError("cannot write '" + file.string() + "': " + std::strerror(errno) + " (check 'path' and --out)",
                        path_where_, ctx.node);
    summary.files.push_back(file.string());
    summary.metric("rows", static_cast<double>(total_rows_));
    if (total_rows_ == 0) summary.notes.push_back("no rows: no initialised estimate" +
                                                  std::string(include_measurements_ ? " or valid measurement" : "") +
                                                  " reached this sink");
  }

 private:
  // Rows leave in arrival order once all truth of their time step can have arrived (a later
  // truth sample has), or at the end of the run. The file is the same whichever happens.
  void flush(bool end_of_run) {
    while (head_ < pending_.size() && (end_of_run || !truth_input_ || pending_[head_].time + kTimeTolerance < latest_truth_))
      write(pending_[head_++]);
    if (head_ == pending_.size()) {
      pending_.clear();
      head_ = 0;
    }
  }

  // The truth sample at `t`: the one of the same target if present, else the only target
  // sampled at that time (filters need not number tracks the way the simulator numbers targets).
  const Truth* truth_at(double t, std::uint32_t target, bool by_target) const {
    auto it = std::lower_bound(truth_.begin(), truth_.end(), t - kTimeTolerance,
                               [](const Truth& s, double time) { return s.time < time; });
    const Truth* same = nullptr;
    const Truth* any = nullptr;
    bool one_target = true;
    for (; it != truth_.end() && it->time <= t + kTimeTolerance; ++it) {
      if (by_target && it->target == target && (!same || std::abs(it->time - t) < std::abs(same->time - t))) same = &*it;
      if (any && any->target != it->target) one_target = false;
      if (!any || std::abs(it->time - t) < std::abs(any->time - t)) any = &*it;
    }
    if (same) return same;
    return one_target ? any : nullptr;
  }

  void write(const PendingRow& r) {
    csv::RowWriter w(rows_, precision_);
    w.integer(run_);
    w.real(r.time);
    if (r.port >= 0 && static_cast<size_t>(r.port) < sources_.size()) {
      w.text(sources_[static_cast<size_t>(r.port)]);
    } else {
      char name[24];
      std::snprintf(name, sizeof name, "input%d", r.port);  // set_inputs was not called (direct use)
      w.text(name);
    }
    w.text(r.measurement ? "measurement" : "estimate");
    if (r.measurement)
      w.empty();
    else
      w.text(r.updated ? "1" : "0");
    for (int i = 0; i < 6; ++i) w.real_if(i < 3 || r.has_velocity, r.value(i));
    for (int i = 0; i < 6; ++i) w.real_if(r.has_sigma && (i < 3 || r.has_velocity), r.sigma(i));
    w.real_if(!r.measurement && r.updated, r.nis);
    const Truth* t = truth_at(r.time, r.target, !r.measurement);
    Vec6 truth = Vec6::Zero();
    if (t) truth << t->position, t->velocity;
    double nees = std::numeric_limits<double>::quiet_NaN();
    if (t && !r.measurement && r.covariance.allFinite()) {
      const Eigen::LLT<Mat6> llt(r.covariance);
      if (llt.info() == Eigen::Success) nees = llt.matrixL().solve(r.value - truth).squaredNorm();
    }
    w.real(nees);
    for (int i = 0; i < 6; ++i) w.real_if(t != nullptr, truth(i));
    std::fill(row_annotations_.begin(), row_annotations_.end(), std::numeric_limits<double>::quiet_NaN());
    if (!r.measurement && r.port >= 0 && static_cast<size_t>(r.port) < column_of_.size()) {
      const auto& columns = column_of_[static_cast<size_t>(r.port)];
      for (int i = 0; i < r.annotation_count && static_cast<size_t>(i) < columns.size(); ++i)
        row_annotations_[static_cast<size_t>(columns[static_cast<size_t>(i)])] = r.annotations[i];
    }
    if (full_covariance_)
      for (int i = 0; i < 6; ++i)
        for (int j = i; j < 6; ++j) w.real_if(r.has_sigma && (j < 3 || r.has_velocity), r.covariance(i, j));
    for (double a : row_annotations_) w.real_if(!std::isnan(a), a);
    w.end();
    ++row_count_;
  }

  const std::string path_;
  const SourceLoc path_where_;
  const bool include_measurements_;
  const bool full_covariance_;
  const int precision_;
  std::vector<std::string> sources_;
  std::vector<std::string> annotation_columns_;
  std::vector<std::vector<int>> column_of_;  // per input port: annotation index -> column
  std::vector<double> row_annotations_;      // scratch of one row, sized once
  bool truth_input_ = true;  // until set_inputs says otherwise, rows wait for truth
  // Per run.
  std::uint64_t run_ = 0;
  std::vector<Truth> truth_;  // time-sorted
  std::vector<PendingRow> pending_;
  size_t head_ = 0;
  double latest_truth_ = -std::numeric_limits<double>::infinity();
  std::string rows_;
  std::uint64_t row_count_ = 0;
  // Aggregating instance.
  std::string file_;
  std::uint64_t total_rows_ = 0;
};

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "sink.csv";
  d.kind = ComponentKind::Sink;
  d.summary = "Writes estimates (any number of filters), optional measurements and matching truth of all runs to one CSV file";
  d.doc =
      "Columns: run,time,source,kind,updated,x,y,z,vx,vy,vz,sigma_x..sigma_vz,nis,nees,truth_x..truth_vz"
      "[,cov_x_x,cov_x_y,...,cov_vz_vz], then one column per annotation the pipeline's adapters publish on the "
      "estimates of this sink's inputs, named <adapter id>.<name> (e.g. qs.grade_range: adapt.quality_switch's "
      "grade, 0 best, 1 normal, 2 worst; adaptive_r.sigma_x: adapt.innovation_r's adapted sigma, m), empty when the "
      "adapter has published none yet. source is the upstream node id; kind is estimate or measurement. Truth "
      "columns and nees are filled when a truth sample lies within 1 us of the row's time, nis when the estimate "
      "was updated; missing values are empty cells. With full_covariance: true, 21 more columns hold the upper "
      "triangle of the ENU covariance row by row (x y z vx vy vz; m2, m2/s, m2/s2; Cartesian measurement rows: their "
      "position block). "
      "Measurement rows carry the Cartesian position (spherical ones converted) and, when Cartesian, the sigmas "
      "of the covariance diagonal. Only initialised estimates and valid measurements are written. Rows are in "
      "run order, then arrival order, so the file is identical for a given seed whatever the thread count.";
  d.params = {
      ParamSpec::string("path", "output file relative to --out (default: <node id>.csv)"),
      ParamSpec::boolean("include_measurements", "also write measurement rows").def("false"),
      ParamSpec::boolean("full_covariance",
                         "also write the upper triangle of the ENU covariance (cov_x_x ... cov_vz_vz; m2, m2/s, m2/s2)")
          .def("false"),
      ParamSpec::integer("precision", "significant digits of numbers").def("10").at_least(1).at_most(17),
  };
  d.accepts = ItemKind::Estimate | ItemKind::Truth | mask(ItemKind::Measurement);
  d.min_inputs = 1;
  d.max_inputs = -1;
  d.produces = 0;
  d.create = [](const Params& p) { return std::make_unique<CsvSink>(p); };
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("sink.csv", trackflow::register_components)
