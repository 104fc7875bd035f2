// Purpose: source.csv — replays a recorded radar log (CSV with a header row) as Measurements, or as Scans of detections grouped by a scan column or by time, checking every row.
#include "csv_text.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <trackflow/common_params.hpp>
#include <trackflow/data_files.hpp>
#include <trackflow/geometry.hpp>
#include <trackflow/number_range.hpp>
#include <trackflow/number_text.hpp>
#include <trackflow/plugin.hpp>
#include <trackflow/scan.hpp>

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <numbers>

namespace trackflow {
namespace {

namespace fs = std::filesystem;

// A column the source reads: the parameter that named it, the header name, its position.
struct Column {
  std::string param;
  std::string name;
  int index = -1;  // -1: not read
  bool read() const { return index >= 0; }
};

std::string format_number(double v) {
  return number_text::general(v, 10);
}

enum class LogFrame { Spherical, Cartesian, Polar, Planar };
enum class TimeUnit { Second, Millisecond };
enum class LengthUnit { Metre, Kilometre };
enum class AngleUnit { Degree, Radian, Milliradian };
enum class OnBadRow { Error, Skip };
enum class Content { Measurements, Detections, Truth };

double angle_scale(AngleUnit unit) {
  if (unit == AngleUnit::Degree) return std::numbers::pi / 180.0;
  if (unit == AngleUnit::Milliradian) return 1e-3;
  return 1.0;
}

double length_scale(LengthUnit unit) { return unit == LengthUnit::Kilometre ? 1e3 : 1.0; }

ParamSpec length_unit_param(const char* name, const char* doc) {
  return ParamSpec::choice<LengthUnit>(name, {{LengthUnit::Metre, "m"}, {LengthUnit::Kilometre, "km"}}, doc).def("m");
}

// Relative paths are relative to the pipeline file that wrote them, so a pipeline and its data
// can move together; paths given on the command line (--set) stay relative to the working directory.
fs::path resolve_path(const Params& p) {
  fs::path path(p.text("path"));
  const std::string& written_in = p.where("path").file;
  std::error_code ec;
  if (path.is_relative() && !written_in.empty() && fs::is_regular_file(written_in, ec))
    path = fs::path(written_in).parent_path() / path;
  return path;
}

// An open log, closed with its last user.
struct FileHandle {
  int fd = -1;
  FileHandle() = default;
  FileHandle(const FileHandle&) = delete;
  FileHandle& operator=(const FileHandle&) = delete;
  ~FileHandle() {
    if (fd >= 0) ::close(fd);
  }
};

// What says that the file was not rewritten since it was checked.
struct FileStamp {
  std::uint64_t size = 0;
  std::int64_t mtime_s = 0, mtime_ns = 0, inode = 0;
  bool operator==(const FileStamp&) const = default;
};

FileStamp stamp_of(const struct stat& st) {
  return {static_cast<std::uint64_t>(st.st_size), static_cast<std::int64_t>(st.st_mtim.tv_sec),
          static_cast<std::int64_t>(st.st_mtim.tv_nsec), static_cast<std::int64_t>(st.st_ino)};
}

// Opens the log for reading (it is streamed, never read whole: any size will do).
void open_file(const Params& p, const fs::path& path, FileHandle& file, FileStamp& stamp) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw p.error("path", "'" + path.string() + "' is a directory, not a CSV file");
  // A FIFO would block and a device (/dev/zero) never end: only regular files are logs.
  const fs::file_status st = fs::status(path, ec);
  if (!ec && fs::exists(st) && !fs::is_regular_file(st))
    throw p.error("path", "'" + path.string() + "' is not a regular file");
  // O_NONBLOCK: a file swapped for a FIFO after the check must not block the open either.
  file.fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (file.fd < 0) {
    const int error = errno;
    // The path as resolved, absolute, and how it was resolved: a relative path is read from the
    // pipeline file's folder, not from where trackflow was started (issue 26).
    std::error_code ignored;
    const fs::path absolute = fs::absolute(path, ignored).lexically_normal();
    const std::string& written = p.text("path");
    std::string how;
    const std::string& written_in = p.where("path").file;
    if (fs::path(written).is_relative())
      how = " (path '" + written + "' is read relative to " +
            (!written_in.empty() && fs::is_regular_file(written_in, ignored)
                 ? "the folder of the file that names it, '" + written_in + "'"
                 : std::string("the working directory")) +
            ")";
    throw p.error("path", "cannot open '" + absolute.string() + "': " + std::strerror(error) + how);
  }
  struct stat info;
  if (::fstat(file.fd, &info) != 0) throw p.error("path", "cannot read '" + path.string() + "': " + std::strerror(errno));
  if (!S_ISREG(info.st_mode)) throw p.error("path", "'" + path.string() + "' is not a regular file");
  stamp = stamp_of(info);
}

// A cell of the file as a message may quote it: the offending token only, short, no control
// characters (the file may not be a log at all).
constexpr std::size_t kTokenChars = 40;
std::string token(std::string_view s) {
  std::string t;
  for (std::size_t i = 0; i < s.size() && i < kTokenChars; ++i) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    t += c < 0x20 || c == 0x7f ? '?' : static_cast<char>(c);
  }
  return s.size() > kTokenChars ? t + "..." : t;
}

// Whether a header looks like column names (so that listing it quotes no content of a file
// that is not a log, e.g. the first line of a system file).
bool plausible_header(const std::vector<std::string>& names) {
  if (names.empty() || names.size() > 256) return false;
  for (const auto& n : names) {
    if (n.empty() || n.size() > 64) return false;
    for (char c : n)
      if (!(std::isalnum(static_cast<unsigned char>(c)) || std::string_view(" _-.()[]/%#+").find(c) != std::string_view::npos))
        return false;
  }
  return true;
}

// The columns a source may read, in the order their positions are kept.
constexpr int kColumns = 15;

// What checking the whole file found, shared read-only by every instance (one per worker
// thread, plus the one that aggregates) built from the same file and parameters. No rows are
// kept: each instance streams them from the file again in every run, through a buffer the size
// of the longest line, with the same parser, so memory does not grow with the log.
struct CheckedLog {
  FileHandle file;
  FileStamp stamp;
  // Where the data rows are: bytes [data_begin, data_end), the first on line first_data_line.
  std::uint64_t data_begin = 0, data_end = 0;
  bool last_terminated = true;
  int first_data_line = 0;
  int header_line = 0;
  std::size_t field_count = 0;
  int column_index[kColumns] = {};
  std::size_t buffer = 0;            // a stream buffer that holds every data line
  std::size_t good_rows = 0;         // rows replayed in a run
  std::vector<std::string> skipped;  // the first kMaxSkipMessages messages
  std::size_t skipped_count = 0;
  std::size_t rows_read = 0;
  std::size_t scans = 0, largest_scan = 0;  // content: detections
  double largest_range = 0;  // frame spherical or polar: of the good rows, in m
};
constexpr std::size_t kMaxSkipMessages = 1000;

// Files checked by this process, by path, file identity and parameters. Weak: a log is freed
// with its last instance, except the latest one, kept so that `validate`'s build and the run's
// instances share one check.
struct LogCache {
  std::mutex mutex;
  std::map<std::string, std::weak_ptr<const CheckedLog>> logs;
  std::shared_ptr<const CheckedLog> latest;
};
LogCache& log_cache() {
  static LogCache* cache = new LogCache();  // never destroyed: instances may outlive statics
  return *cache;
}

std::string cache_key(const Params& p, const fs::path& path) {
  std::error_code ec;
  std::string key = path.string() + '\n' + fs::canonical(path, ec).string() + '\n';
  const auto size = fs::file_size(path, ec);
  const auto mtime = fs::last_write_time(path, ec);
  key += std::to_string(size) + '\n' + std::to_string(mtime.time_since_epoch().count()) + '\n';
  char buf[40];
  for (const auto& [name, v] : p.values()) {
    key += name + '=';
    switch (v.type) {
      case ParamType::Real: std::snprintf(buf, sizeof buf, "%.17g", v.real); key += buf; break;
      case ParamType::Integer: key += std::to_string(v.integer); break;
      case ParamType::Boolean: key += v.boolean ? "1" : "0"; break;
      case ParamType::String: key += v.text; break;
      case ParamType::Choice: key += std::to_string(v.choice); break;
      case ParamType::RealList:
        for (double x : v.reals) {
          std::snprintf(buf, sizeof buf, "%.17g,", x);
          key += buf;
        }
        break;
      case ParamType::Records:
      case ParamType::Component:
      case ParamType::ComponentList: break;
    }
    key += '\n';
  }
  return key;
}

class CsvSource final : public Generator {
 public:
  explicit CsvSource(const Params& p) : node_(p.node()), skip_bad_rows_(p.choice<OnBadRow>("on_bad_row") == OnBadRow::Skip) {
    configure(p);
    current_ = prototype_;  // checking parses into it
    const fs::path path = resolve_path(p);
    file_ = path.string();
    note_data_file(file_);  // the ranks of an MPI job compare its size and content hash
    const std::string key = cache_key(p, path);
    LogCache& cache = log_cache();
    // Held while checking: instances built at the same time wait for the one check and share it.
    std::lock_guard<std::mutex> lock(cache.mutex);
    if (auto it = cache.logs.find(key); it != cache.logs.end()) log_ = it->second.lock();
    if (!log_) {
      auto checked = std::make_shared<CheckedLog>();
      open_file(p, path, checked->file, checked->stamp);
      check(*checked);
      log_ = checked;
      for (auto it = cache.logs.begin(); it != cache.logs.end();)
        it = it->second.expired() ? cache.logs.erase(it) : std::next(it);
      cache.logs[key] = log_;
    }
    cache.latest = log_;
    warn_if_ranges_short(p);
    for (int i = 0; i < kColumns; ++i) columns()[i]->index = log_->column_index[i];
    field_count_ = log_->field_count;
    header_number_ = log_->header_line;
    // Sized for the longest data line: replaying never allocates.
    stream_ = csv::LineStream(log_->buffer);
    fields_.reserve(field_count_ + 1);
    detections_.reserve(log_->largest_scan);
  }

  // A surveillance or tracking radar's log whose every range is under 100 m is almost always a log
  // in km read as metres (issue 26: it otherwise shows only as a "near the zenith" warning).
  void warn_if_ranges_short(const Params& p) const {
    if ((frame_ != Frame::Spherical && frame_ != Frame::Polar) || content_ == Content::Truth) return;
    if (log_->good_rows == 0 || log_->largest_range >= 100.0 || log_->largest_range == 0.0) return;
    p.warn(p.given("range_unit") ? "range_unit" : "path",
           "every range in '" + file_ + "' is under 100 m (the largest is " + number_text::general(log_->largest_range, 4) +
               " m, read with range_unit: " + p.choice_word("range_unit") + "): a log in km read as metres? give range_unit: km");
  }

  void start_run(const RunContext& ctx) override {
    // A log rewritten since it was checked would replay rows nobody checked.
    struct stat info;
    if (::fstat(log_->file.fd, &info) != 0 || !(stamp_of(info) == log_->stamp))
      fail(file_ + ": the file changed after it was checked when the pipeline was built; do not rewrite a log while "
                   "a pipeline reads it");
    stream_.open(log_->file.fd, log_->data_begin, log_->data_end, log_->last_terminated, log_->first_data_line);
    has_previous_ = false;
    replayed_ = left_out_ = 0;
    has_current_ = false;
    // Every instance replays the same rows; only run 0 reports, so each bad row is counted once.
    if (ctx.run == 0 && ctx.diagnostics) {
      for (const auto& message : log_->skipped) ctx.diagnostics->skip(node_, message);
      if (log_->skipped_count > log_->skipped.size())
        ctx.diagnostics->skip(node_, "... and " + std::to_string(log_->skipped_count - log_->skipped.size()) +
                                         " more bad rows left out (all counted in skipped_rows)");
    }
    advance();
  }

  FrameMask produced_frames() const override { return mask(frame_); }
  ItemMask produced_kinds() const override {
    return mask(content_ == Content::Detections ? ItemKind::Scan
                : content_ == Content::Truth    ? ItemKind::Truth
                                                : ItemKind::Measurement);
  }

  double next_time() const override { return has_current_ ? current_.time : std::numeric_limits<double>::infinity(); }

  void emit_next() override {
    if (!has_current_) return;
    if (content_ == Content::Measurements) {
      out.emit(current_);
      advance();
      return;
    }
    if (content_ == Content::Truth) {
      truth_.time = current_.time;
      truth_.target = row_target_;
      truth_.position = current_.value.head<3>();
      truth_.velocity = row_velocity_;
      out.emit(truth_);
      advance();
      return;
    }
    // One scan: this row and every following one of the same scan (a look without detections is
    // a row with no values). Its time and sensor are its first row's.
    detections_.clear();
    static_cast<SensorFrame&>(scan_.sensor) = current_;
    scan_.time = current_.time;
    const double time = current_.time;
    const std::uint32_t key = row_scan_;
    do {
      if (!row_empty_) detections_.push_back(static_cast<const Detection&>(current_));
      advance();
    } while (has_current_ && same_scan(time, key, current_.time, row_scan_));
    scan_.detections = std::span<const Detection>(detections_.data(), detections_.size());
    out.emit(scan_);
  }

  void finish(Summary& s, const FinishContext&) override {
    s.metric("rows", static_cast<double>(log_->rows_read));
    s.metric("skipped_rows", static_cast<double>(log_->skipped_count));
    if (content_ == Content::Detections) s.metric("scans", static_cast<double>(log_->scans));
  }

 private:
  std::array<Column*, kColumns> columns() {
    return {&time_, &value_[0], &value_[1], &value_[2], &range_rate_, &snr_, &mode_, &valid_, &sensor_, &scan_id_, &origin_,
            &target_, &velocity_[0], &velocity_[1], &velocity_[2]};
  }

  // Rows of one scan: the same scan id with a scan column, else the same time.
  bool same_scan(double time, std::uint32_t key, double t, std::uint32_t k) const {
    return scan_id_.read() ? k == key : t == time;
  }

  void configure(const Params& p) {
    content_ = p.choice<Content>("content");
    const bool detections = content_ == Content::Detections;
    for (const char* name : {"scan_column", "detection_probability", "clutter_density"})
      if (!detections && p.given(name)) throw p.error(name, "applies only to content: detections (rows grouped into scans)");
    if (detections && p.given("valid_column"))
      throw p.error("valid_column", "applies to content: measurements; in a log of detections every row is a detection, and a "
                                    "look that saw nothing is a row whose value cells are empty");
    scan_.detection_probability = p.has("detection_probability") ? p.real("detection_probability") : std::numeric_limits<double>::quiet_NaN();
    scan_.clutter_density = p.has("clutter_density") ? p.real("clutter_density") : std::numeric_limits<double>::quiet_NaN();
    if (content_ == Content::Truth) {
      if (p.choice<LogFrame>("frame") != LogFrame::Cartesian)
        throw p.error(p.given("frame") ? "frame" : "content", "a truth log holds ENU positions: give frame: cartesian");
      for (const char* name : {"range_rate_column", "snr_column", "mode_column", "valid_column", "sensor_column",
                               "origin_column", "sigma_position", "sigma_range_rate"})
        if (p.given(name)) throw p.error(name, "applies to logs of measurements or detections, not to content: truth");
      const int velocities = p.given("vx_column") + p.given("vy_column") + p.given("vz_column");
      if (velocities != 0 && velocities != 3)
        throw p.error(p.given("vx_column") ? "vx_column" : p.given("vy_column") ? "vy_column" : "vz_column",
                      "give vx_column, vy_column and vz_column together (or none: velocity 0)");
    } else {
      for (const char* name : {"target_column", "vx_column", "vy_column", "vz_column"})
        if (p.given(name)) throw p.error(name, "applies only to content: truth");
    }
    const LogFrame log_frame = p.choice<LogFrame>("frame");
    // Positions in x, y (, z): Cartesian and planar; in range, azimuth (, elevation): spherical and polar.
    const bool cartesian = log_frame == LogFrame::Cartesian || log_frame == LogFrame::Planar;
    frame_ = log_frame == LogFrame::Cartesian ? Frame::Cartesian
             : log_frame == LogFrame::Planar  ? Frame::Planar
             : log_frame == LogFrame::Polar   ? Frame::Polar
                                              : Frame::Spherical;
    positions_ = position_values(frame_);
    // A parameter of the other frame would be silently ignored; say so instead.
    const std::vector<const char*> spherical_only = {"range_column", "azimuth_column", "elevation_column",
                                                     "range_unit",   "angle_unit",     "sigma_range",
                                                     "sigma_azimuth", "sigma_elevation"};
    const std::vector<const char*> cartesian_only = {"x_column", "y_column", "z_column", "position_unit",
                                                     "sigma_position"};
    for (const char* name : cartesian ? spherical_only : cartesian_only)
      if (p.given(name))
        throw p.error(name, std::string("applies only to frame: ") + (cartesian ? "spherical or polar" : "cartesian or planar") +
                                ", and this source reads frame: " + p.choice_word("frame"));
    // The value a 2-D frame does not have.
    const char* unmeasured = frame_ == Frame::Polar ? "elevation_column" : frame_ == Frame::Planar ? "z_column" : nullptr;
    if (unmeasured && p.given(unmeasured))
      throw p.error(unmeasured, std::string("frame: ") + p.choice_word("frame") + " has no " +
                                    (frame_ == Frame::Polar ? "elevation (a 2-D radar)" : "z (a planar sensor)"));
    if (frame_ == Frame::Polar && p.given("sigma_elevation"))
      throw p.error("sigma_elevation", "frame: polar has no elevation (a 2-D radar)");
    if (frame_ == Frame::Planar && p.has("range_rate_column"))
      throw p.error("range_rate_column", "frame: planar has no range rate (a position sensor of the plane)");
    if (p.given("sigma_range_rate") && !p.has("range_rate_column"))
      throw p.error("sigma_range_rate", "applies only when range_rate_column names the range-rate column");

    time_scale_ = p.choice<TimeUnit>("time_unit") == TimeUnit::Millisecond ? 1e-3 : 1.0;
    auto column = [&](const char* param) {
      Column c;
      c.param = param;
      if (p.has(param)) c.name = p.text(param);
      return c;
    };
    time_ = column("time_column");
    if (cartesian) {
      value_[0] = column("x_column");
      value_[1] = column("y_column");
      if (positions_ == 3) value_[2] = column("z_column");
      const double length = length_scale(p.choice<LengthUnit>("position_unit"));
      scale_[0] = scale_[1] = scale_[2] = length;
      rdot_scale_ = length;
    } else {
      value_[0] = column("range_column");
      value_[1] = column("azimuth_column");
      if (positions_ == 3) value_[2] = column("elevation_column");
      const double length = length_scale(p.choice<LengthUnit>("range_unit"));
      const double angle = angle_scale(p.choice<AngleUnit>("angle_unit"));
      scale_[0] = length;
      scale_[1] = scale_[2] = angle;
      rdot_scale_ = length;
    }
    range_rate_ = column("range_rate_column");
    snr_ = column("snr_column");
    mode_ = column("mode_column");
    valid_ = column("valid_column");
    sensor_ = column("sensor_column");
    scan_id_ = column("scan_column");
    origin_ = column("origin_column");
    if (content_ == Content::Truth) {
      target_ = column("target_column");
      velocity_[0] = column("vx_column");
      velocity_[1] = column("vy_column");
      velocity_[2] = column("vz_column");
    }

    Measurement& m = prototype_;
    m.frame = frame_;
    m.azimuth = p.choice<AzimuthConvention>("azimuth_convention");
    m.sensor = static_cast<std::uint32_t>(p.integer("sensor_id"));
    m.sensor_position = p.vec3("position");
    m.has_range_rate = !range_rate_.name.empty();
    const int n = positions_ + (m.has_range_rate ? 1 : 0);
    m.value = MeasVec::Zero(n);
    m.covariance = MeasCov::Zero(n, n);
    if (cartesian) {
      const double s = p.real("sigma_position");
      for (int i = 0; i < positions_; ++i) m.covariance(i, i) = s * s;
    } else {
      const double sr = p.real("sigma_range"), sa = p.real("sigma_azimuth"), se = p.real("sigma_elevation");
      m.covariance(0, 0) = sr * sr;
      m.covariance(1, 1) = sa * sa;
      if (positions_ == 3) m.covariance(2, 2) = se * se;
    }
    if (m.has_range_rate)
      m.covariance(positions_, positions_) = p.real("sigma_range_rate") * p.real("sigma_range_rate");
  }

  std::string at(int line) const { return file_ + ":" + std::to_string(line) + ": "; }

  [[noreturn]] void fail(const std::string& message) const { throw DataError(message); }

  // Finds every named column in the header; a missing one is fatal whatever on_bad_row says.
  void locate_columns(const csv::Line& header_line, const std::vector<std::string_view>& header) {
    std::vector<std::string> names(header.begin(), header.end());
    const bool listable = plausible_header(names);
    auto listing = [&] {
      std::string l;
      for (const auto& n : names) l += (l.empty() ? "" : ", ") + ("'" + n + "'");
      return l;
    };
    for (Column* c : columns()) {
      if (c->name.empty()) continue;
      int found = -1, count = 0;
      for (std::size_t i = 0; i < names.size(); ++i)
        if (names[i] == c->name) {
          if (found < 0) found = static_cast<int>(i);
          ++count;
        }
      if (count == 0) {
        if (!listable)
          fail(at(header_line.number) + "no column '" + c->name + "' (" + c->param +
               "): the first line does not look like a header of column names (is 'path' the right file?)");
        fail(at(header_line.number) + "no column '" + c->name + "' (" + c->param + ") in the header" +
             csv::did_you_mean(c->name, names) + "; the header has " + std::to_string(names.size()) +
             " column(s): " + listing() + "; if the file names it differently, set " + c->param);
      }
      if (count > 1)
        fail(at(header_line.number) + "column '" + c->name + "' (" + c->param + ") appears " + std::to_string(count) +
             " times in the header; rename one so the source knows which to read");
      c->index = found;
    }
    field_count_ = names.size();
  }

  // Reads the whole file once, line by line, and checks every row: a bad row stops the pipeline
  // here (or is counted, with on_bad_row: skip), so `trackflow validate` finds data problems too.
  void check(CheckedLog& log) {
    try {
      // Blank lines after the last non-blank one are fine: find where the content ends first.
      const std::uint64_t end = csv::content_end(log.file.fd, log.stamp.size);
      csv::LineStream& reader = stream_;
      reader.open(log.file.fd, 0, end, log.stamp.size > end, 1);
      csv::Line header_line;
      // Leading blank lines are skipped.
      bool have_header = false;
      while (reader.next(header_line))
        if (!csv::is_blank(header_line.text)) {
          have_header = true;
          break;
        }
      if (!have_header) fail(file_ + ": the file is empty; expected a header row, then one row per measurement");

      std::vector<std::string_view>& fields = fields_;
      if (std::string why = csv::split_fields(header_line.text, fields); !why.empty())
        fail(at(header_line.number) + "header: " + why);
      // A UTF-8 byte-order mark (spreadsheet exports) is not part of the first column's name.
      if (!fields.empty() && fields[0].starts_with("\xEF\xBB\xBF")) {
        fields[0].remove_prefix(3);
        if (!fields[0].empty() && fields[0].front() == '"' && fields[0].size() >= 2 && fields[0].back() == '"')
          fields[0] = fields[0].substr(1, fields[0].size() - 2);
      }
      locate_columns(header_line, fields);
      header_number_ = header_line.number;
      if (reader.done()) fail(at(header_line.number) + "the file has a header but no data rows");

      log.header_line = header_line.number;
      log.field_count = field_count_;
      for (int i = 0; i < kColumns; ++i) log.column_index[i] = columns()[i]->index;
      log.data_begin = reader.offset();
      log.data_end = end;
      log.last_terminated = log.stamp.size > end;
      log.first_data_line = header_line.number + 1;

      std::size_t longest = 0;
      double group_time = 0.0;
      std::uint32_t group_key = 0;
      std::size_t group_size = 0;
      csv::Line line;
      std::string why;
      while (reader.next(line)) {
        ++log.rows_read;
        longest = std::max(longest, line.text.size());
        if (read_row(line, reader.done(), fields, current_, &why)) {
          ++log.good_rows;
          if ((frame_ == Frame::Spherical || frame_ == Frame::Polar) && content_ != Content::Truth && !row_empty_)
            log.largest_range = std::max(log.largest_range, std::abs(current_.value(0)));
          if (content_ == Content::Detections) {
            if (log.scans == 0 || !same_scan(group_time, group_key, current_.time, row_scan_)) {
              ++log.scans;
              group_time = current_.time;
              group_key = row_scan_;
              group_size = 0;
            }
            if (!row_empty_) log.largest_scan = std::max(log.largest_scan, ++group_size);
          }
          continue;
        }
        why = at(line.number) + why;
        if (!skip_bad_rows_) fail(why);
        if (log.skipped.size() < kMaxSkipMessages) log.skipped.push_back(std::move(why));
        ++log.skipped_count;
      }
      // With room for a stripped "\r\n": a replay then never grows its buffer.
      log.buffer = std::max(csv::LineStream::kDefaultCapacity, longest + 2);
    } catch (const csv::ReadError& e) {
      fail(e.line > 0 ? at(e.line) + e.what() : file_ + ": " + e.what());
    }
  }

  // Moves current_ to the next good row of this run (has_current_ false at the end). The rows were
  // checked when the pipeline was built, so only a file rewritten since makes one fail here.
  void advance() {
    has_current_ = false;
    try {
      csv::Line line;
      while (stream_.next(line)) {
        if (read_row(line, stream_.done(), fields_, current_, nullptr)) {
          ++replayed_;
          has_current_ = true;
          return;
        }
        if (!skip_bad_rows_) {
          std::string why;
          read_row(line, stream_.done(), fields_, current_, &why);
          fail(at(line.number) + why + " (the file changed after it was checked when the pipeline was built)");
        }
        ++left_out_;
      }
    } catch (const csv::ReadError& e) {
      fail(file_ + ": the file changed after it was checked when the pipeline was built (" + e.what() + ")");
    }
    if (replayed_ != log_->good_rows || left_out_ != log_->skipped_count)
      fail(file_ + ": the file changed after it was checked when the pipeline was built (" + std::to_string(replayed_) +
           " good rows now, " + std::to_string(log_->good_rows) + " then)");
  }

  // Fills `m` from one data line; true if it is a good row. Otherwise `why`, if given, says what
  // is wrong with the line; without it nothing is built (a skipped row replayed in a run).
  bool read_row(const csv::Line& line, bool last, std::vector<std::string_view>& fields, Measurement& m,
                std::string* why) {
    m.snr_db = prototype_.snr_db;
    m.has_snr = prototype_.has_snr;
    m.mode = prototype_.mode;
    m.valid = prototype_.valid;
    m.sensor = prototype_.sensor;
    auto reject = [why](auto&& message) {
      if (why) *why = message();
      return false;
    };
    const std::string_view truncated =
        last && !line.terminated ? "the last line looks truncated (no newline at the end of the file): " : "";
    if (csv::is_blank(line.text))
      return reject([&] {
        return "empty line inside the data (expected " + std::to_string(field_count_) + " fields as in the header)";
      });
    if (std::string e = csv::split_fields(line.text, fields); !e.empty())
      return reject([&] { return std::string(truncated) + e; });
    if (fields.size() != field_count_)
      return reject([&] {
        const std::string counts = "expected " + std::to_string(field_count_) + " fields as in the header (line " +
                                   std::to_string(header_number_) + "), got " + std::to_string(fields.size());
        if (last && fields.size() < field_count_)
          return "truncated last line: " + counts + (line.terminated ? "" : " (no newline at the end of the file)");
        return "wrong number of fields: " + counts;
      });

    auto complain = [&](std::string_view prefix, std::string_view what, const Column& c) {
      return reject([&] {
        return std::string(prefix) + std::string(what) + " (column " + c.name + ", value '" + token(fields[c.index]) + "')";
      });
    };
    // An empty or half-written cell on an unterminated last line is most likely a cut-off write.
    auto real = [&](const Column& c, double& v) {
      switch (csv::parse_real(fields[c.index], v)) {
        case csv::CellStatus::Ok: return true;
        case csv::CellStatus::Empty: return complain(truncated, "empty value where a number is expected", c);
        case csv::CellStatus::NotFinite: return complain("", "NaN or infinite value", c);
        case csv::CellStatus::OutOfRange:
          return complain("", std::string("number ") +
                                  number_range::describe(number_range::classify(fields[c.index])),
                          c);
        case csv::CellStatus::Malformed: return complain(truncated, "not a number", c);
      }
      return false;
    };

    double t = 0.0;
    if (!real(time_, t)) return false;
    t *= time_scale_;
    if (has_previous_ && t < previous_time_) {
      if (!why) return false;
      return complain("",
                      "time goes backwards: earlier than " +
                          token(std::string_view(previous_time_text_, previous_time_length_)) + " on line " +
                          std::to_string(previous_line_),
                      time_);
    }
    m.time = t;
    if (scan_id_.read() && csv::parse_id(fields[scan_id_.index], row_scan_) != csv::CellStatus::Ok)
      return complain("", "not a scan id (expected a non-negative integer)", scan_id_);
    // A log of detections writes a look that saw nothing as a row without values.
    row_empty_ = content_ == Content::Detections && no_values(fields);
    if (row_empty_) {
      remember_time(line, fields, t);
      return true;
    }
    for (int k = 0; k < positions_; ++k) {
      double v = 0.0;
      if (!real(value_[k], v)) return false;
      m.value(k) = v * scale_[k];
      // Finite in the file's unit is not enough: 1e306 km is infinite in metres.
      if (!std::isfinite(m.value(k))) return complain("", "value overflows when converted to SI", value_[k]);
    }
    if (has_azimuth(m.frame)) {
      if (m.value(0) < 0.0) return complain("", "negative range", value_[0]);
      if (m.frame == Frame::Spherical && std::fabs(m.value(2)) > std::numbers::pi / 2 * (1 + 1e-12))
        return complain("", "elevation beyond +-90 deg", value_[2]);
      // A log writes its azimuths in [0, 360) or (-180, 180] deg; one beyond a full turn (1e300,
      // accepted and wrapped before, issue 27) is a corrupt cell, refused as the elevation above.
      if (std::fabs(m.value(1)) > 2 * std::numbers::pi * (1 + 1e-12))
        return complain("", "azimuth beyond +-360 deg", value_[1]);
      m.value(1) = wrap_angle(m.value(1));
    }
    if (range_rate_.read()) {
      double v = 0.0;
      if (!real(range_rate_, v)) return false;
      m.value(positions_) = v * rdot_scale_;
      if (!std::isfinite(m.value(positions_))) return complain("", "value overflows when converted to SI", range_rate_);
    }
    if (snr_.read()) {
      if (!real(snr_, m.snr_db)) return false;
      m.has_snr = true;
    }
    if (mode_.read()) {
      const std::string_view mode = fields[mode_.index];
      m.mode = csv::iequals(mode, "beacon") ? MeasMode::Beacon
               : csv::iequals(mode, "skin") ? MeasMode::Skin
                                             : MeasMode::Unknown;
    }
    if (valid_.read() && csv::parse_flag(fields[valid_.index], m.valid) != csv::CellStatus::Ok)
      return complain("", "not a validity flag (expected 1, 0, true or false)", valid_);
    if (sensor_.read() && csv::parse_id(fields[sensor_.index], m.sensor) != csv::CellStatus::Ok)
      return complain("", "not a sensor id (expected a non-negative integer)", sensor_);
    if (target_.read() && csv::parse_id(fields[target_.index], row_target_) != csv::CellStatus::Ok)
      return complain("", "not a target id (expected a non-negative integer)", target_);
    for (int k = 0; k < 3; ++k) {
      if (!velocity_[k].read()) {
        row_velocity_[k] = 0.0;
        continue;
      }
      double v = 0.0;
      if (!real(velocity_[k], v)) return false;
      row_velocity_[k] = v * scale_[k];  // the position unit per second
      if (!std::isfinite(row_velocity_[k])) return complain("", "value overflows when converted to SI", velocity_[k]);
    }
    m.origin = kOriginUnknown;
    if (origin_.read()) {
      const std::string_view o = fields[origin_.index];
      if (csv::iequals(o, "clutter"))
        m.origin = kOriginClutter;
      else if (!csv::is_blank(o) && (csv::parse_id(o, m.origin) != csv::CellStatus::Ok || m.origin >= kOriginClutter))
        return complain("", "not an origin (expected a target id, 'clutter', or nothing for unknown)", origin_);
    }
    remember_time(line, fields, t);
    return true;
  }

  // Whether every value cell of the row (and its range rate's) is empty.
  bool no_values(const std::vector<std::string_view>& fields) const {
    for (const Column* c : {&value_[0], &value_[1], &value_[2], &range_rate_})
      if (c->read() && !csv::is_blank(fields[c->index])) return false;
    return true;
  }

  // The time order of the good rows: what a later row is compared with.
  void remember_time(const csv::Line& line, const std::vector<std::string_view>& fields, double t) {
    has_previous_ = true;
    previous_time_ = t;
    // The line's text is gone once the stream reads on: keep what token() may quote of it (one
    // character more than it shows, so that it still knows whether to cut).
    const std::string_view time_text = fields[time_.index];
    previous_time_length_ = std::min(time_text.size(), sizeof previous_time_text_);
    std::memcpy(previous_time_text_, time_text.data(), previous_time_length_);
    previous_line_ = line.number;
  }

  // Configuration.
  std::string node_;
  bool skip_bad_rows_ = false;
  std::string file_;
  Content content_ = Content::Measurements;
  int positions_ = 3;  // position values per row: 3, or 2 for the polar and planar frames
  Column time_, value_[3], range_rate_, snr_, mode_, valid_, sensor_, scan_id_, origin_, target_, velocity_[3];
  double time_scale_ = 1.0, scale_[3] = {1.0, 1.0, 1.0}, rdot_scale_ = 1.0;
  Measurement prototype_;
  std::size_t field_count_ = 0;
  int header_number_ = 1;

  // Reading state, reset at each run: the time order of the good rows.
  bool has_previous_ = false;
  double previous_time_ = 0.0;
  char previous_time_text_[kTokenChars + 1] = {};
  std::size_t previous_time_length_ = 0;
  int previous_line_ = 0;

  // The replayed data: checked once, shared; streamed again by each instance in every run.
  std::shared_ptr<const CheckedLog> log_;
  csv::LineStream stream_;
  std::vector<std::string_view> fields_;
  Measurement current_;  // the row to emit next (the prototype with its fields)
  bool has_current_ = false;
  std::size_t replayed_ = 0, left_out_ = 0;  // good and bad rows of this run so far
  Frame frame_ = Frame::Spherical;
  // content: detections — the scan being gathered, and what the last row read was.
  std::vector<Detection> detections_;
  Scan scan_;
  std::uint32_t row_scan_ = 0;
  bool row_empty_ = false;
  // content: truth — the row's target id and velocity, and the item emitted.
  std::uint32_t row_target_ = 0;
  Vec3 row_velocity_ = Vec3::Zero();
  Truth truth_;
};

std::vector<ParamSpec> csv_params() {
  using P = ParamSpec;
  return {
      P::string("path", "CSV file; a relative path is relative to the pipeline file's folder").req(),
      P::choice<LogFrame>("frame",
                          {{LogFrame::Spherical, "spherical"},
                           {LogFrame::Cartesian, "cartesian"},
                           {LogFrame::Polar, "polar"},
                           {LogFrame::Planar, "planar"}},
                          "what the rows hold: range/azimuth/elevation, x/y/z ENU, a 2-D radar's range/azimuth "
                          "(polar), or a planar sensor's x/y (planar)")
          .def("spherical"),
      P::string("time_column", "column with the measurement time").def("time"),
      P::string("range_column", "spherical, polar: column with the range").def("range"),
      P::string("azimuth_column", "spherical, polar: column with the azimuth").def("azimuth"),
      P::string("elevation_column", "spherical: column with the elevation").def("elevation"),
      P::string("range_rate_column", "column with the range rate (length unit per second); read only if given"),
      P::string("x_column", "cartesian, planar: column with x (east)").def("x"),
      P::string("y_column", "cartesian, planar: column with y (north)").def("y"),
      P::string("z_column", "cartesian: column with z (up)").def("z"),
      P::string("snr_column", "column with the signal-to-noise ratio in dB; read only if given"),
      P::string("mode_column", "column with the track mode: beacon or skin (any case), anything else is unknown"),
      P::string("valid_column", "column with the validity flag: 1/0/true/false; invalid rows make filters coast"),
      P::string("sensor_column", "column with the sensor id (non-negative integer); overrides sensor_id"),
      P::choice<Content>("content",
                         {{Content::Measurements, "measurements"}, {Content::Detections, "detections"}, {Content::Truth, "truth"}},
                         "what the source emits: one measurement per row, scans of detections (rows grouped by "
                         "scan_column, or by equal time), or one truth per row (to score recorded data)")
          .def("measurements"),
      P::string("scan_column", "detections: column with the scan number (non-negative integer); consecutive rows with "
                               "the same number are one scan (default: rows of equal time)"),
      P::string("target_column", "truth: column with the target id (non-negative integer)").def("target"),
      P::string("vx_column", "truth: column with the east velocity (position unit per second; with vy, vz; default 0)"),
      P::string("vy_column", "truth: column with the north velocity"),
      P::string("vz_column", "truth: column with the up velocity"),
      P::string("origin_column", "column with each row's origin, for scoring: a target id, 'clutter', or empty (unknown)"),
      P::real("detection_probability", dim::none, "detections: the P_D the scans state (default: not stated)").at_least(0).at_most(1),
      P::real("clutter_density", Dimension{}, "detections: the clutter density the scans state, per unit of measurement "
                                              "space (m3, or m rad2 for spherical; default: not stated)").at_least(0),
      P::choice<TimeUnit>("time_unit", {{TimeUnit::Second, "s"}, {TimeUnit::Millisecond, "ms"}}, "unit of the time column")
          .def("s"),
      length_unit_param("range_unit", "spherical, polar: unit of range (and range rate per second)"),
      P::choice<AngleUnit>("angle_unit",
                           {{AngleUnit::Degree, "deg"}, {AngleUnit::Radian, "rad"}, {AngleUnit::Milliradian, "mrad"}},
                           "spherical, polar: unit of azimuth and elevation")
          .def("deg"),
      length_unit_param("position_unit", "cartesian, planar: unit of x, y, z (and range rate per second)"),
      P::real("sigma_range", dim::length, "spherical, polar: range noise standard deviation").def("10 m").positive(),
      P::real("sigma_azimuth", dim::angle, "spherical, polar: azimuth noise standard deviation").def("1 mrad").positive()
          .plausible_up_to(kPlausibleAngleSigma, kAngleSigmaHint),
      P::real("sigma_elevation", dim::angle, "spherical: elevation noise standard deviation").def("1 mrad").positive()
          .plausible_up_to(kPlausibleAngleSigma, kAngleSigmaHint),
      P::real("sigma_range_rate", dim::velocity, "range-rate noise standard deviation").def("1 m/s").positive(),
      P::real("sigma_position", dim::length, "cartesian, planar: noise standard deviation of each position value")
          .def("10 m")
          .positive(),
      P::real_list("position", dim::length, "sensor position in the ENU frame [x, y, z]", 3).def("[0, 0, 0]"),
      azimuth_convention_param("how the file's azimuth is measured: compass bearing, or from east toward north"),
      P::integer("sensor_id", "sensor id of every row (unless sensor_column is given)")
          .def("0")
          .at_least(0)
          .at_most(std::numeric_limits<std::uint32_t>::max()),
      P::choice<OnBadRow>("on_bad_row", {{OnBadRow::Error, "error"}, {OnBadRow::Skip, "skip"}},
                "a malformed row stops the pipeline (error) or is left out and reported (skip)")
          .def("error"),
  };
}

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "source.csv";
  d.kind = ComponentKind::Source;
  d.summary = "Recorded radar log (CSV with a header row) replayed as measurements, in file order";
  d.doc = "The whole file is read and checked when the pipeline is built, so `trackflow validate` also finds data "
          "problems; each run then streams the rows from the file again through a buffer of the longest line, so "
          "memory does not grow with the length of the log (a file rewritten while the pipeline runs is an error). "
          "Each bad row (not a number, NaN/inf, a number beyond a double's range (too large, or too small: an "
          "underflow such as 1e-400), wrong field count, negative range, an elevation beyond +-90 deg or an azimuth "
          "beyond +-360 deg, time going backwards, truncated last line) is reported as FILE:LINE; with on_bad_row: skip it is left out and counted. "
          "Accepts CRLF line endings and double-quoted fields without embedded commas. Metrics: rows (data rows "
          "read), skipped_rows.\n"
          "content: detections replays the log as scans (Scan items) for a tracker: consecutive rows of one scan "
          "(the same scan_column value, or without it the same time) are the detections of one look, at its first "
          "row's time and sensor; a row whose value cells are all empty is a look that saw nothing (a scan with "
          "no detections, which a tracker counts as a miss for every track, unlike no scan at all). origin_column "
          "labels rows for scoring (a target id, 'clutter', or empty for unknown); estimators never read it. The "
          "scans state no region; their P_D and clutter density are the parameters' when given, else unknown "
          "(NaN: give the associator its own). Metrics add scans.\n"
          "content: truth replays a truth log (frame: cartesian): per row one Truth of target target_column at "
          "x, y, z (position_unit) with velocity vx, vy, vz when those columns are given (else 0) and acceleration 0, "
          "in time order, so a recorded run (e.g. GPS or ADS-B reference positions) can be scored by the sinks.\n"
          "frame: polar reads a 2-D surveillance radar's rows (range_column, azimuth_column; no elevation), frame: "
          "planar a planar position sensor's (x_column, y_column; no z, no range rate): two position values per "
          "row, sigma_range/sigma_azimuth or sigma_position for their covariance.";
  d.params = csv_params();
  d.min_inputs = 0;
  d.max_inputs = 0;
  // One of the three, as `content` says (produced_kinds).
  d.produces = mask(ItemKind::Measurement) | mask(ItemKind::Scan) | mask(ItemKind::Truth);
  d.time_ordered = true;  // rows out of time order are refused or skipped (on_bad_row)
  d.create = [](const Params& p) { return std::make_unique<CsvSource>(p); };
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("source.csv", trackflow::register_components)
