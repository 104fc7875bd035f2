// Purpose: sink.csv — one CSV file of all runs: estimates of any number of filters, optional measurements, matching truth and NEES.
#include "csv_row.hpp"

#include <trackflow/geometry.hpp>
#include <trackflow/output_path.hpp>
#include <trackflow/plugin.hpp>
#include <trackflow/run_result_codec.hpp>
#include <trackflow/safe_output.hpp>
#include <trackflow/scan.hpp>
#include <trackflow/tracks.hpp>

#include <unistd.h>

#include <Eigen/Cholesky>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <filesystem>
#include <fstream>
#include <limits>

namespace trackflow {
namespace {

// Units in the column names (SI; "/" written "_per_"), so pandas.read_csv gives named, unit-carrying
// columns (issue 26: the README said every output carries its units).
constexpr const char* kHeader =
    "run,time_s,source,kind,updated,x_m,y_m,z_m,vx_m_per_s,vy_m_per_s,vz_m_per_s,"
    "sigma_x_m,sigma_y_m,sigma_z_m,sigma_vx_m_per_s,sigma_vy_m_per_s,sigma_vz_m_per_s,nis,nees,"
    "truth_x_m,truth_y_m,truth_z_m,truth_vx_m_per_s,truth_vy_m_per_s,truth_vz_m_per_s";

// With an input of track sets (a tracker): each track's id and status, after the truth columns.
constexpr const char* kTrackHeader = ",track_id,track_status";

// With an input of scans: each detection's origin (a target id, clutter, or empty: unknown).
constexpr const char* kOriginHeader = ",origin";

// Opt-in (full_covariance): the upper triangle of the ENU covariance, row by row; units m2,
// m2/s and m2/s2 in the names (the sigma_* columns are the square roots of its diagonal).
constexpr const char* kCovarianceHeader =
    ",cov_x_x_m2,cov_x_y_m2,cov_x_z_m2,cov_x_vx_m2_per_s,cov_x_vy_m2_per_s,cov_x_vz_m2_per_s"
    ",cov_y_y_m2,cov_y_z_m2,cov_y_vx_m2_per_s,cov_y_vy_m2_per_s,cov_y_vz_m2_per_s,cov_z_z_m2"
    ",cov_z_vx_m2_per_s,cov_z_vy_m2_per_s,cov_z_vz_m2_per_s,cov_vx_vx_m2_per_s2,cov_vx_vy_m2_per_s2"
    ",cov_vx_vz_m2_per_s2,cov_vy_vy_m2_per_s2,cov_vy_vz_m2_per_s2,cov_vz_vz_m2_per_s2";

// Truth samples within this of an item's time are its truth (the same default as sink.metrics).
constexpr double kTimeTolerance = 1e-6;
// Truth older than this before the latest item (and every pending row) is no longer kept.
constexpr double kPruneMargin = 1.0;

// An anonymous temporary file (unlinked at once: nothing is left behind, whatever happens).
struct TempFile {
  std::FILE* f = nullptr;
  TempFile() = default;
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;
  ~TempFile() {
    if (f) std::fclose(f);
  }
};

struct CsvRunResult final : RunResult {
  std::unique_ptr<TempFile> spilled;  // the run's first rows, when they outgrew memory
  std::string rows;                   // the rest
  std::uint64_t count = 0;
  std::uint64_t non_finite = 0;
  std::string first_non_finite;       // "run 3, t=1.5 s, column x"
};

// An item waiting for the truth of its time step, which may arrive after it.
struct PendingRow {
  double time = 0.0;
  int port = 0;
  std::uint32_t target = 0;
  bool measurement = false;        // a measurement or a scan's detection: no estimate columns
  bool detection = false;          // a scan's detection: kind "detection", its origin written
  std::uint32_t origin = kOriginUnknown;
  bool track = false;              // a tracker's track: its id and status are written
  std::uint64_t track_id = 0;
  TrackStatus status = TrackStatus::Tentative;
  bool updated = false;
  bool has_nis = false;
  bool has_velocity = false;
  bool has_sigma = false;
  std::uint8_t sigma_missing = 0;  // bit i: variance i negative, so sigma i has no value
  double nis = 0.0;
  Vec6 value = Vec6::Zero();
  Vec6 sigma = Vec6::Zero();
  Mat6 covariance = Mat6::Zero();  // estimates: for NEES
  double annotations[kMaxAnnotations] = {};  // estimates: their filter's adapter annotations
  int annotation_count = 0;
};

// A run's rows in memory up to this size; beyond, they go to a temporary file next to the
// output, so a 10^6-step run never holds its whole text.
constexpr std::size_t kSpillBytes = std::size_t{4} << 20;

// A new anonymous temporary file in `dir` (created if missing), or null when none can be made
// there (the rows then stay in memory).
std::unique_ptr<TempFile> make_spill_file(const std::string& dir, const std::string& node) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(dir, ec);
  std::string pattern = (fs::path(dir) / ("." + node + ".run-XXXXXX")).string();
  const int fd = ::mkstemp(pattern.data());
  if (fd < 0) return nullptr;
  ::unlink(pattern.c_str());
  auto spill = std::make_unique<TempFile>();
  spill->f = ::fdopen(fd, "w+b");
  if (!spill->f) {
    ::close(fd);
    return nullptr;
  }
  return spill;
}

// Under mpirun a run's rows travel as chunks of at most this size (the spill file is read
// back this much at a time), ended by an empty chunk.
constexpr std::size_t kChunkBytes = std::size_t{1} << 20;

std::string column_name(int column, const std::vector<std::string>& annotation_columns, bool tracks, bool scans,
                        bool full_covariance) {
  std::string header = kHeader;
  if (tracks) header += kTrackHeader;
  if (scans) header += kOriginHeader;
  if (full_covariance) header += kCovarianceHeader;
  for (const auto& a : annotation_columns) header += "," + a;
  int c = 0;
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = header.find(',', start);
    if (c == column) return header.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    if (comma == std::string::npos) return "?";
    start = comma + 1;
    ++c;
  }
}

class CsvSink final : public Component, public RunResultCodec {
 public:
  explicit CsvSink(const Params& p)
      : path_(p.has("path") ? p.text("path") : std::string()),
        path_where_(p.where("path")),
        node_(p.node()),
        include_measurements_(p.boolean("include_measurements")),
        include_detections_(p.boolean("include_detections")),
        full_covariance_(p.boolean("full_covariance")),
        precision_(p.has("precision") ? static_cast<int>(p.integer("precision")) : csv::RowWriter::kShortest) {
    if (p.has("path") && path_.empty()) throw p.error("path", "must not be empty (leave it out for '<node id>.csv')");
    // A pipeline file from someone else must not write anywhere but under --out.
    if (std::string why = output_path_problem(path_); !why.empty())
      throw p.error("path", why + " (pass --allow-outside-out on the command line to allow it)");
    // Checked by the host against the run's other outputs (two sinks, the report, series files).
    declare_output_file(node_, path_.empty() ? node_ + ".csv" : path_);
    truth_.reserve(4096);
    pending_.reserve(1024);
  }

  // An ensemble that did not finish leaves no half-written file under the real name: the
  // temporary of out_ (safe_output.hpp) is removed by its destructor.
  ~CsvSink() override = default;

  void set_inputs(const std::vector<InputInfo>& inputs) override {
    sources_.clear();
    annotation_columns_.clear();
    column_of_.clear();
    truth_input_ = false;
    tracks_input_ = false;
    scans_input_ = false;
    for (const auto& in : inputs) {
      sources_.push_back(csv::quoted(in.node));
      truth_input_ |= (in.kinds & mask(ItemKind::Truth)) != 0;
      tracks_input_ |= (in.kinds & mask(ItemKind::Tracks)) != 0;
      scans_input_ |= include_detections_ && (in.kinds & mask(ItemKind::Scan)) != 0;
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
    head_ = 0;
    rows_.clear();
    spill_.reset();
    row_count_ = 0;
    non_finite_ = 0;
    first_non_finite_.clear();
    in_time_order_ = true;
    latest_arrival_ = -std::numeric_limits<double>::infinity();
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
    arrived(t.time);
    flush(false);
  }

  void on_estimate(const Estimate& e, int port) override {
    if (!e.initialised) return;
    PendingRow& r = pending_.emplace_back();
    fill_from(r, e, e.time, port);
    r.annotation_count = e.annotation_count;
    for (int i = 0; i < e.annotation_count; ++i) r.annotations[i] = e.annotations[i];
    arrived(e.time);
    flush(false);
  }

  // An estimate's (or a track's) cells: ENU state, sigmas, NIS, its target for the truth.
  static void fill_from(PendingRow& r, const Estimate& e, double time, int port) {
    r.time = time;
    r.port = port;
    r.target = e.target;
    r.updated = e.updated;
    r.has_nis = e.updated && e.innovation.size() > 0;
    r.nis = e.nis;
    r.value = e.enu;
    r.has_velocity = true;
    r.has_sigma = true;
    r.sigma_missing = 0;
    for (int i = 0; i < 6; ++i) {
      const double v = e.enu_covariance(i, i);
      r.sigma(i) = std::sqrt(v);
      if (v < 0.0) r.sigma_missing |= static_cast<std::uint8_t>(1u << i);  // NaN stays a value: "nan"
    }
    r.covariance = e.enu_covariance;
  }

  // One row per track of the set (deleted ones once, with their last state), kind "track".
  void on_tracks(const TrackSet& set, int port) override {
    for (const TrackEstimate& te : set.tracks) {
      const Estimate& e = te.estimate;
      if (!e.initialised) continue;
      PendingRow& r = pending_.emplace_back();
      fill_from(r, e, set.time, port);
      // A tracker's per-track adapters' values (tracker.multi `adapters:`), named in InputInfo::annotations.
      r.annotation_count = e.annotation_count;
      for (int i = 0; i < e.annotation_count; ++i) r.annotations[i] = e.annotations[i];
      r.track = true;
      r.track_id = te.id;
      r.status = te.status;
    }
    arrived(set.time);
    flush(false);
  }

  // One row per detection of the scan, kind "detection": its position in the frame, its origin,
  // and the truth of its origin target (none for clutter or an unknown origin).
  void on_scan(const Scan& s, int port) override {
    if (!include_detections_) return;
    for (const Detection& d : s.detections) {
      if (d.value.size() < position_values(s.sensor.frame)) continue;
      to_measurement(s, d, detection_);
      PendingRow& r = add_measurement_row(detection_, port);
      r.detection = true;
      r.origin = d.origin;
      r.target = d.origin;
    }
    arrived(s.time);
    flush(false);
  }

  void on_measurement(const Measurement& m, int port) override {
    if (!include_measurements_ || !m.valid || m.value.size() < m.position_dim()) return;
    add_measurement_row(m, port);
    arrived(m.time);
    flush(false);
  }

  // A measurement's cells: the Cartesian position (a spherical or polar one converted, a planar
  // one in z = 0) and, when Cartesian or planar, the sigmas of its covariance diagonal.
  PendingRow& add_measurement_row(const Measurement& m, int port) {
    PendingRow& r = pending_.emplace_back();
    r.time = m.time;
    r.port = port;
    r.measurement = true;
    r.sigma_missing = 0;
    if (m.frame == Frame::Cartesian || m.frame == Frame::Planar) {
      // A planar position lies in z = 0: its z and z sigma are 0, not unknown.
      const int k = m.position_dim();
      r.value.head<3>() = measured_position(m);
      r.has_sigma = m.covariance.rows() >= k && m.covariance.cols() >= k;
      if (r.has_sigma) r.sigma.setZero();
      for (int i = 0; i < k && r.has_sigma; ++i) {
        const double v = m.covariance(i, i);
        r.sigma(i) = std::sqrt(v);
        if (v < 0.0) r.sigma_missing |= static_cast<std::uint8_t>(1u << i);
      }
      if (r.has_sigma) {
        r.covariance.topLeftCorner<3, 3>().setZero();
        r.covariance.topLeftCorner(k, k) = m.covariance.topLeftCorner(k, k);
      }
    } else {
      r.value.head<3>() = measured_position(m);
    }
    return r;
  }

  std::unique_ptr<RunResult> end_run() override {
    flush(true);
    auto r = std::make_unique<CsvRunResult>();
    r->spilled = std::move(spill_);
    // The text moves into the result (no copy of the run's text) unless that would leave it
    // holding more than twice its size (a run smaller than an earlier one, or a spilled run's
    // tail): then it is copied. The next run starts with room for as much as this one.
    const std::size_t size = rows_.size();
    if (rows_.capacity() / 2 <= size) {
      r->rows = std::move(rows_);
      rows_ = std::string();
      rows_.reserve(size);
    } else {
      r->rows = rows_;
    }
    r->count = row_count_;
    r->non_finite = non_finite_;
    r->first_non_finite = first_non_finite_;
    return r;
  }

  // A run's rows cross processes under mpirun as the exact bytes it would have appended to the
  // file (spilled part first, then the rest), so the merged file is byte-identical. The sender
  // holds one run's text in its message; the receiver (rank 0, where finished runs may wait for
  // an earlier one) moves the rows of a large run to a temporary file again, so waiting runs
  // do not pile up in memory.
  void save_run_result(const RunResult& result, ByteWriter& out) const override {
    const auto& r = static_cast<const CsvRunResult&>(result);
    out.put(r.count);
    out.put(r.non_finite);
    out.put_string(r.first_non_finite);
    if (r.spilled) {
      std::FILE* f = r.spilled->f;
      std::rewind(f);
      std::string chunk(kChunkBytes, '\0');
      for (std::size_t n; (n = std::fread(chunk.data(), 1, chunk.size(), f)) > 0;) {
        chunk.resize(n);
        out.put_string(chunk);
        chunk.resize(kChunkBytes);
      }
      if (std::ferror(f)) throw DataError("sink.csv (node '" + node_ + "'): cannot read back its temporary file");
    }
    for (std::size_t at = 0; at < r.rows.size(); at += kChunkBytes)
      out.put_string(r.rows.substr(at, kChunkBytes));
    out.put_string(std::string());
  }
  std::unique_ptr<RunResult> load_run_result(ByteReader& in) const override {
    auto r = std::make_unique<CsvRunResult>();
    in.get(r->count);
    in.get(r->non_finite);
    r->first_non_finite = in.get_string();
    for (;;) {
      const std::string chunk = in.get_string();
      if (chunk.empty()) break;
      r->rows += chunk;
      if (r->rows.size() < kSpillBytes || output_directory().empty()) continue;
      if (!r->spilled) r->spilled = make_spill_file(output_directory(), node_);
      if (!r->spilled) continue;  // no temporary file possible: stays in memory
      if (std::fwrite(r->rows.data(), 1, r->rows.size(), r->spilled->f) != r->rows.size())
        throw ConfigError(std::string("cannot write a temporary file in the output folder: ") + std::strerror(errno),
                          path_where_, node_);
      r->rows.clear();
    }
    return r;
  }

  void merge(RunResult& result) override {
    auto& r = static_cast<CsvRunResult&>(result);
    total_rows_ += r.count;
    if (r.non_finite && !non_finite_total_) first_non_finite_total_ = r.first_non_finite;
    non_finite_total_ += r.non_finite;
    // Streamed in run order into the file while the ensemble runs (the engine tells every
    // thread the output folder), so memory does not grow with the ensemble.
    if (!out_.is_open() && !output_directory().empty()) open(output_directory());
    if (out_.is_open()) {
      if (r.spilled) append_file(r.spilled->f);
      put(r.rows.data(), r.rows.size());
    } else {
      if (r.spilled) {
        std::rewind(r.spilled->f);
        char buf[1 << 16];
        for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, r.spilled->f)) > 0;) file_.append(buf, n);
      }
      file_ += r.rows;
    }
  }

  void finish(Summary& summary, const FinishContext& ctx) override {
    if (!out_.is_open()) open(ctx.output_dir);
    put(file_.data(), file_.size());
    file_.clear();
    if (!out_.commit()) fail_write();
    summary.files.push_back(file_path_.string());
    summary.metric("rows", static_cast<double>(total_rows_));
    if (total_rows_ == 0) summary.notes.push_back("no rows: no initialised estimate" +
                                                  std::string(include_measurements_ ? " or valid measurement" : "") +
                                                  " reached this sink");
    // A NaN that reached the file is written as "nan", never hidden as an empty (missing) cell,
    // and it fails the run: some upstream node produced it.
    if (non_finite_total_)
      throw DataError("wrote " + std::to_string(non_finite_total_) +
                      " non-finite value(s) (nan/inf) into " + file_path_.string() + ", the first in " +
                      first_non_finite_total_ + "; an upstream node produced them");
  }

 private:
  void open(const std::string& output_dir) {
    namespace fs = std::filesystem;
    file_path_ = fs::path(output_dir.empty() ? "." : output_dir) / (path_.empty() ? node_ + ".csv" : path_);
    // Folders beneath --out opened without following symlinks, a unique temporary renamed
    // into place at finish (safe_output.hpp, issue 27).
    if (!out_.open_beneath(output_dir.empty() ? "." : output_dir, path_.empty() ? node_ + ".csv" : path_))
      throw ConfigError(out_.error() + " (check 'path' and --out)", path_where_, node_);
    std::string header = kHeader;
    if (tracks_input_) header += kTrackHeader;
    if (scans_input_) header += kOriginHeader;
    if (full_covariance_) header += kCovarianceHeader;
    for (const auto& name : annotation_columns_) header += ',' + csv::quoted(name);
    header += '\n';
    put(header.data(), header.size());
  }

  void put(const char* data, std::size_t n) {
    if (!out_.write(data, n)) fail_write();
  }

  void append_file(std::FILE* in) {
    std::rewind(in);
    char buf[1 << 16];
    for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, in)) > 0;) put(buf, n);
    if (std::ferror(in)) throw DataError("sink.csv (node '" + node_ + "'): cannot read back its temporary file");
  }

  // A full disk is an error of the run, found when it happens, not a file silently cut short.
  [[noreturn]] void fail_write() {
    throw ConfigError(out_.error() + " (check the space on the disk, 'path' and --out)", path_where_, node_);
  }

  // Moves the rows of this run to a temporary file in the output folder when they outgrow
  // memory. Without an output folder (a component used directly) they stay in memory.
  void maybe_spill() {
    if (rows_.size() < kSpillBytes || output_directory().empty()) return;
    if (!spill_) spill_ = make_spill_file(output_directory(), node_);
    if (!spill_) return;  // stays in memory
    if (std::fwrite(rows_.data(), 1, rows_.size(), spill_->f) != rows_.size())
      throw ConfigError(std::string("cannot write a temporary file in the output folder: ") + std::strerror(errno),
                        path_where_, node_);
    rows_.clear();
  }

  // Rows leave in arrival order once all truth of their time step can have arrived (a later
  // truth sample has), or at the end of the run. The file is the same whichever happens.
  void flush(bool end_of_run) {
    while (head_ < pending_.size() && (end_of_run || !truth_input_ || pending_[head_].time + kTimeTolerance < latest_truth_))
      write(pending_[head_++]);
    if (head_ == pending_.size()) {
      pending_.clear();
      head_ = 0;
    } else if (head_ >= 1024 && 2 * head_ >= pending_.size()) {
      // Written rows leave the queue even while one always waits (the estimate of a step
      // arrives before the truth of the next): the queue holds a few rows, not the run.
      pending_.erase(pending_.begin(), pending_.begin() + static_cast<std::ptrdiff_t>(head_));
      head_ = 0;
    }
    prune_truth();
    maybe_spill();
  }

  // Items reach a sink in time order (sources are merged by time); what arrives more than
  // kPruneMargin before the latest item means they do not, and truth is then kept whole.
  void arrived(double t) {
    if (t < latest_arrival_ - kPruneMargin) in_time_order_ = false;
    latest_arrival_ = std::max(latest_arrival_, t);
  }

  // Truth samples no future row can match are dropped, so a long run keeps a window of truth,
  // not all of it: future rows come no earlier than kPruneMargin before the latest item (time
  // order), pending rows are kept with theirs. Pruning stops for the run if the order breaks.
  void prune_truth() {
    if (truth_.size() < 8192 || !in_time_order_) return;
    double needed = latest_arrival_;
    for (std::size_t i = head_; i < pending_.size(); ++i) needed = std::min(needed, pending_[i].time);
    const double keep_from = needed - kPruneMargin - 2 * kTimeTolerance;
    auto it = std::lower_bound(truth_.begin(), truth_.end(), keep_from,
                               [](const Truth& s, double time) { return s.time < time; });
    if (it - truth_.begin() > static_cast<std::ptrdiff_t>(truth_.size() / 2)) truth_.erase(truth_.begin(), it);
  }

  // The truth sample at `t`: the one of the same target if present, else the only target
  // sampled at that time (filters need not number tracks the way the simulator numbers targets);
  // `strict` (a tracker's track, whose target is the origin of its initiating detections): only
  // the same target.
  const Truth* truth_at(double t, std::uint32_t target, bool by_target, bool strict = false) const {
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
    if (same || strict) return same;
    return one_target ? any : nullptr;
  }

  void write(const PendingRow& r) {
    csv::RowWriter w(rows_, precision_);
    w.integer(run_);
    w.real(r.time);
    if (r.port >= 0 && static_cast<size_t>(r.port) < sources_.size()) {
      w.text(sources_[static_cast<size_t>(r.port)]);
    } else {
      w.text("input" + std::to_string(r.port));  // set_inputs was not called (direct use)
    }
    w.text(r.detection ? "detection" : r.measurement ? "measurement" : r.track ? "track" : "estimate");
    if (r.measurement)
      w.empty();
    else
      w.text(r.updated ? "1" : "0");
    for (int i = 0; i < 6; ++i) w.real_if(i < 3 || r.has_velocity, r.value(i));
    for (int i = 0; i < 6; ++i)
      w.real_if(r.has_sigma && (i < 3 || r.has_velocity) && !(r.sigma_missing & (1u << i)), r.sigma(i));
    w.real_if(!r.measurement && r.has_nis, r.nis);
    // A detection's truth is its origin target's only (clutter and unknown origins have none).
    const Truth* t = r.detection ? (r.origin < kOriginClutter ? truth_at(r.time, r.target, true, true) : nullptr)
                                 : truth_at(r.time, r.target, !r.measurement, r.track);
    Vec6 truth = Vec6::Zero();
    if (t) truth << t->position, t->velocity;
    double nees = 0.0;
    bool has_nees = false;
    if (t && !r.measurement && r.covariance.allFinite()) {
      const Eigen::LLT<Mat6> llt(r.covariance);
      if (llt.info() == Eigen::Success) {
        nees = llt.matrixL().solve(r.value - truth).squaredNorm();
        has_nees = true;
      }
    }
    w.real_if(has_nees, nees);
    for (int i = 0; i < 6; ++i) w.real_if(t != nullptr, truth(i));
    if (tracks_input_) {
      if (r.track) {
        w.integer(r.track_id);
        w.text(to_string(r.status));
      } else {
        w.empty();
        w.empty();
      }
    }
    if (scans_input_) {
      if (r.detection && r.origin == kOriginClutter)
        w.text("clutter");
      else if (r.detection && r.origin != kOriginUnknown)
        w.integer(r.origin);
      else
        w.empty();
    }
    std::fill(row_annotations_.begin(), row_annotations_.end(), std::numeric_limits<double>::quiet_NaN());
    if (!r.measurement && r.port >= 0 && static_cast<size_t>(r.port) < column_of_.size()) {
      const auto& columns = column_of_[static_cast<size_t>(r.port)];
      for (int i = 0; i < r.annotation_count && static_cast<size_t>(i) < columns.size(); ++i)
        row_annotations_[static_cast<size_t>(columns[static_cast<size_t>(i)])] = r.annotations[i];
    }
    if (full_covariance_)
      for (int i = 0; i < 6; ++i)
        for (int j = i; j < 6; ++j) w.real_if(r.has_sigma && (j < 3 || r.has_velocity), r.covariance(i, j));
    // NaN is an adapter's "no value yet" (Adapter::annotate): empty.
    for (double a : row_annotations_) w.real_if(!std::isnan(a), a);
    w.end();
    ++row_count_;
    if (w.non_finite()) {
      if (non_finite_ == 0) {
        first_non_finite_ = "run " + std::to_string(run_) + ", t=" + number_text::general(r.time, 10) + " s, column " +
                            column_name(w.first_non_finite_column(), annotation_columns_, tracks_input_, scans_input_, full_covariance_);
      }
      non_finite_ += static_cast<std::uint64_t>(w.non_finite());
    }
  }

  const std::string path_;
  const SourceLoc path_where_;
  const std::string node_;
  const bool include_measurements_;
  const bool include_detections_;  // rows for the detections of scan inputs (a scenario's truth input also carries scans)
  const bool full_covariance_;
  const int precision_;  // csv::RowWriter::kShortest unless given
  std::vector<std::string> sources_;
  std::vector<std::string> annotation_columns_;
  std::vector<std::vector<int>> column_of_;  // per input port: annotation index -> column
  std::vector<double> row_annotations_;      // scratch of one row, sized once
  bool truth_input_ = true;  // until set_inputs says otherwise, rows wait for truth
  bool tracks_input_ = false;  // an input of track sets: the track_id and track_status columns
  bool scans_input_ = false;   // an input of scans: the origin column
  Measurement detection_;      // a scan's detection as a measurement (its position), reused
  // Per run.
  std::uint64_t run_ = 0;
  std::vector<Truth> truth_;  // time-sorted
  std::vector<PendingRow> pending_;
  size_t head_ = 0;
  double latest_truth_ = -std::numeric_limits<double>::infinity();
  double latest_arrival_ = -std::numeric_limits<double>::infinity();
  bool in_time_order_ = true;
  std::string rows_;
  std::unique_ptr<TempFile> spill_;
  std::uint64_t row_count_ = 0;
  std::uint64_t non_finite_ = 0;
  std::string first_non_finite_;
  // Aggregating instance.
  std::string file_;  // rows merged while no output folder was known (direct use)
  SafeOutputFile out_;
  std::filesystem::path file_path_;
  std::uint64_t total_rows_ = 0;
  std::uint64_t non_finite_total_ = 0;
  std::string first_non_finite_total_;
};

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "sink.csv";
  d.kind = ComponentKind::Sink;
  d.summary = "Writes estimates (any number of filters), track sets, scans' detections, optional measurements and matching "
              "truth of all runs to one CSV file";
  d.doc =
      "Columns, SI units in their names: run,time_s,source,kind,updated,x_m,y_m,z_m,vx_m_per_s,vy_m_per_s,vz_m_per_s,"
      "sigma_x_m..sigma_vz_m_per_s,nis,nees,truth_x_m..truth_vz_m_per_s[,cov_x_x_m2,cov_x_y_m2,...,cov_vz_vz_m2_per_s2], "
      "then one column per annotation the pipeline's adapters publish on the "
      "estimates of this sink's inputs, named <adapter id>.<name> (e.g. qs.grade_range: adapt.quality_switch's "
      "grade, 0 best, 1 normal, 2 worst; adaptive_r.sigma_x: adapt.innovation_r's adapted sigma, m), empty when the "
      "adapter has published none yet. source is the upstream node id; kind is estimate, measurement or track. "
      "With an input of track sets (a tracker), two more columns follow the truth: track_id and track_status "
      "(tentative, confirmed, coasting, deleted: a deleted track's last state, once), one row per track per set; "
      "a track's truth is that of its target (the origin of its initiating detections) only. With include_detections: true and an input of scans, "
      "one row per detection, kind detection, its position in the frame (spherical ones converted), its truth that of "
      "its origin target only, and one more column, origin: the target id, clutter, or empty when unknown. Truth "
      "columns and nees are filled when a truth sample lies within 1 us of the row's time, nis when the estimate "
      "was updated; missing values are empty cells, and a value that is NaN or infinite is written as nan, inf or -inf "
      "and fails the run (exit 2). The file is streamed in run order while the ensemble runs (written as a temporary .<file>.<pid>.<random>.partial, "
      "renamed when complete; folders beneath --out are never followed through symbolic links). With full_covariance: true, 21 more columns hold the upper "
      "triangle of the ENU covariance row by row (x y z vx vy vz; m2, m2/s, m2/s2; Cartesian measurement rows: their "
      "position block). "
      "Measurement rows carry the Cartesian position (spherical ones converted) and, when Cartesian, the sigmas "
      "of the covariance diagonal. Only initialised estimates and valid measurements are written. Rows are in "
      "run order, then arrival order, so the file is identical for a given seed whatever the thread count.";
  d.params = {
      ParamSpec::string("path", "output file relative to --out (default: <node id>.csv); absolute paths and '..' are "
                                "refused unless the command line has --allow-outside-out"),
      ParamSpec::boolean("include_measurements", "also write measurement rows").def("false"),
      ParamSpec::boolean("include_detections", "also write a row per detection of the scan inputs (and the origin column)").def("false"),
      ParamSpec::boolean("full_covariance",
                         "also write the upper triangle of the ENU covariance (cov_x_x ... cov_vz_vz; m2, m2/s, m2/s2)")
          .def("false"),
      ParamSpec::integer("precision", "significant digits of numbers (printf %.Ng); left out: the shortest text that "
                                      "reads back as exactly the same double (lossless, e.g. 0.1, 6123.456789012345, 1e-05)")
          .at_least(1)
          .at_most(17),
  };
  d.accepts = ItemKind::Estimate | ItemKind::Truth | mask(ItemKind::Measurement) | mask(ItemKind::Tracks) | mask(ItemKind::Scan);
  d.min_inputs = 1;
  d.max_inputs = -1;
  d.produces = 0;
  d.create = [](const Params& p) { return std::make_unique<CsvSink>(p); };
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("sink.csv", trackflow::register_components)
