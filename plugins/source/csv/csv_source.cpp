// Purpose: source.csv — replays a recorded radar log (CSV with a header row) as Measurements, checking every row.
#include "csv_text.hpp"

#include <trackflow/geometry.hpp>
#include <trackflow/common_params.hpp>
#include <trackflow/plugin.hpp>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
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
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

enum class LogFrame { Spherical, Cartesian };
enum class TimeUnit { Second, Millisecond };
enum class LengthUnit { Metre, Kilometre };
enum class AngleUnit { Degree, Radian, Milliradian };
enum class OnBadRow { Error, Skip };

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

// A log larger than this is refused rather than read into memory.
constexpr std::uintmax_t kMaxFileBytes = std::uintmax_t{1} << 30;

std::string read_file(const Params& p, const fs::path& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw p.error("path", "'" + path.string() + "' is a directory, not a CSV file");
  // A FIFO would block and a device (/dev/zero) never end: only regular files are logs.
  const fs::file_status st = fs::status(path, ec);
  if (!ec && fs::exists(st) && !fs::is_regular_file(st))
    throw p.error("path", "'" + path.string() + "' is not a regular file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw p.error("path", "cannot open '" + path.string() + "': " + std::strerror(errno));
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec) throw p.error("path", "cannot read '" + path.string() + "': " + ec.message());
  if (size > kMaxFileBytes)
    throw p.error("path", "'" + path.string() + "' is larger than 1 GiB; split the log into several files");
  std::string text(static_cast<std::size_t>(size), '\0');
  if (!in.read(text.data(), static_cast<std::streamsize>(text.size())))
    throw p.error("path", "cannot read '" + path.string() + "'");
  return text;
}

// A cell of the file as a message may quote it: the offending token only, short, no control
// characters (the file may not be a log at all).
std::string token(std::string_view s) {
  std::string t;
  for (std::size_t i = 0; i < s.size() && i < 40; ++i) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    t += c < 0x20 || c == 0x7f ? '?' : static_cast<char>(c);
  }
  return s.size() > 40 ? t + "..." : t;
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

// One data row as replayed: what varies between rows (the rest is the source's prototype
// measurement). 56 bytes instead of a whole Measurement, so 2e6 rows take ~110 MB.
struct Row {
  double time = 0.0;
  double value[4] = {};
  double snr_db = 0.0;
  std::uint32_t sensor = 0;
  MeasMode mode = MeasMode::Unknown;
  bool valid = true;
  bool has_snr = false;
};

// The parsed file, shared read-only by every instance (one per worker thread, plus the one
// that aggregates) built from the same file and parameters: parsed once, held once.
struct ParsedLog {
  std::vector<Row> rows;
  std::vector<std::string> skipped;  // the first kMaxSkipMessages messages
  std::size_t skipped_count = 0;
  std::size_t rows_read = 0;
};
constexpr std::size_t kMaxSkipMessages = 1000;

// Files parsed by this process, by path, file identity and parameters. Weak: a log is freed
// with its last instance, except the latest one, kept so that `validate`'s build and the run's
// instances share one parse.
struct LogCache {
  std::mutex mutex;
  std::map<std::string, std::weak_ptr<const ParsedLog>> logs;
  std::shared_ptr<const ParsedLog> latest;
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
      case ParamType::Records: break;
    }
    key += '\n';
  }
  return key;
}

class CsvSource final : public Generator {
 public:
  explicit CsvSource(const Params& p) : node_(p.node()), skip_bad_rows_(p.choice<OnBadRow>("on_bad_row") == OnBadRow::Skip) {
    configure(p);
    const fs::path path = resolve_path(p);
    file_ = path.string();
    const std::string key = cache_key(p, path);
    LogCache& cache = log_cache();
    // Held while parsing: instances built at the same time wait for the one parse and share it.
    std::lock_guard<std::mutex> lock(cache.mutex);
    if (auto it = cache.logs.find(key); it != cache.logs.end()) log_ = it->second.lock();
    if (!log_) {
      auto parsed = std::make_shared<ParsedLog>();
      building_ = parsed.get();
      parse(read_file(p, path));
      building_ = nullptr;
      log_ = parsed;
      for (auto it = cache.logs.begin(); it != cache.logs.end();)
        it = it->second.expired() ? cache.logs.erase(it) : std::next(it);
      cache.logs[key] = log_;
    }
    cache.latest = log_;
    current_ = prototype_;
  }

  void start_run(const RunContext& ctx) override {
    cursor_ = 0;
    // Every instance replays the same rows; only run 0 reports, so each bad row is counted once.
    if (ctx.run == 0 && ctx.diagnostics) {
      for (const auto& message : log_->skipped) ctx.diagnostics->skip(node_, message);
      if (log_->skipped_count > log_->skipped.size())
        ctx.diagnostics->skip(node_, "... and " + std::to_string(log_->skipped_count - log_->skipped.size()) +
                                         " more bad rows left out (all counted in skipped_rows)");
    }
  }

  FrameMask produced_frames() const override { return mask(frame_); }

  double next_time() const override {
    return cursor_ < log_->rows.size() ? log_->rows[cursor_].time : std::numeric_limits<double>::infinity();
  }

  void emit_next() override {
    if (cursor_ >= log_->rows.size()) return;
    const Row& r = log_->rows[cursor_++];
    current_.time = r.time;
    for (int k = 0; k < current_.value.size(); ++k) current_.value(k) = r.value[k];
    current_.snr_db = r.snr_db;
    current_.has_snr = r.has_snr;
    current_.mode = r.mode;
    current_.valid = r.valid;
    current_.sensor = r.sensor;
    out.emit(current_);
  }

  void finish(Summary& s, const FinishContext&) override {
    s.metric("rows", static_cast<double>(log_->rows_read));
    s.metric("skipped_rows", static_cast<double>(log_->skipped_count));
  }

 private:
  void configure(const Params& p) {
    const bool cartesian = p.choice<LogFrame>("frame") == LogFrame::Cartesian;
    frame_ = cartesian ? Frame::Cartesian : Frame::Spherical;
    // A parameter of the other frame would be silently ignored; say so instead.
    const std::vector<const char*> spherical_only = {"range_column", "azimuth_column", "elevation_column",
                                                     "range_unit",   "angle_unit",     "sigma_range",
                                                     "sigma_azimuth", "sigma_elevation"};
    const std::vector<const char*> cartesian_only = {"x_column", "y_column", "z_column", "position_unit",
                                                     "sigma_position"};
    for (const char* name : cartesian ? spherical_only : cartesian_only)
      if (p.given(name))
        throw p.error(name, std::string("applies only to frame: ") + (cartesian ? "spherical" : "cartesian") +
                                ", and this source reads frame: " + p.choice_word("frame"));
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
      value_[2] = column("z_column");
      const double length = length_scale(p.choice<LengthUnit>("position_unit"));
      scale_[0] = scale_[1] = scale_[2] = length;
      rdot_scale_ = length;
    } else {
      value_[0] = column("range_column");
      value_[1] = column("azimuth_column");
      value_[2] = column("elevation_column");
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

    Measurement& m = prototype_;
    m.frame = cartesian ? Frame::Cartesian : Frame::Spherical;
    m.azimuth = p.choice<AzimuthConvention>("azimuth_convention");
    m.sensor = static_cast<std::uint32_t>(p.integer("sensor_id"));
    m.sensor_position = p.vec3("position");
    m.has_range_rate = !range_rate_.name.empty();
    const int n = m.has_range_rate ? 4 : 3;
    m.value = MeasVec::Zero(n);
    m.covariance = MeasCov::Zero(n, n);
    if (cartesian) {
      const double s = p.real("sigma_position");
      m.covariance.diagonal().head<3>().setConstant(s * s);
    } else {
      const double sr = p.real("sigma_range"), sa = p.real("sigma_azimuth"), se = p.real("sigma_elevation");
      m.covariance.diagonal().head<3>() << sr * sr, sa * sa, se * se;
    }
    if (m.has_range_rate) m.covariance(3, 3) = p.real("sigma_range_rate") * p.real("sigma_range_rate");
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
    for (Column* c : {&time_, &value_[0], &value_[1], &value_[2], &range_rate_, &snr_, &mode_, &valid_, &sensor_}) {
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

  void parse(const std::string& text) {
    // Lines are taken one at a time (no table of 2e6 lines); blank lines after the last
    // non-blank one are fine, so find where the content ends first.
    std::size_t content_end = text.size();
    for (;;) {
      const std::size_t nl = content_end == 0 ? std::string::npos : text.rfind('\n', content_end - 1);
      const std::size_t start = nl == std::string::npos ? 0 : nl + 1;
      if (!csv::is_blank(std::string_view(text).substr(start, content_end - start))) break;
      if (start == 0) {
        content_end = 0;
        break;
      }
      content_end = nl;  // drop this blank line (and its newline)
    }
    csv::LineReader reader(std::string_view(text).substr(0, content_end), text.size() > content_end);
    csv::Line header_line;
    // Leading blank lines are skipped.
    bool have_header = false;
    while (reader.next(header_line))
      if (!csv::is_blank(header_line.text)) {
        have_header = true;
        break;
      }
    if (!have_header) fail(file_ + ": the file is empty; expected a header row, then one row per measurement");

    std::vector<std::string_view> fields;
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

    ParsedLog& log = *building_;
    log.rows.reserve(static_cast<std::size_t>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(content_end), '\n')) + 1);
    csv::Line line;
    Measurement m = prototype_;
    while (reader.next(line)) {
      ++log.rows_read;
      const bool last = reader.done();
      std::string why = read_row(line, last, fields, m);
      if (why.empty()) {
        Row& r = log.rows.emplace_back();
        r.time = m.time;
        for (int k = 0; k < m.value.size() && k < 4; ++k) r.value[k] = m.value(k);
        r.snr_db = m.snr_db;
        r.has_snr = m.has_snr;
        r.mode = m.mode;
        r.valid = m.valid;
        r.sensor = m.sensor;
        continue;
      }
      why = at(line.number) + why;
      if (!skip_bad_rows_) fail(why);
      if (log.skipped.size() < kMaxSkipMessages) log.skipped.push_back(std::move(why));
      ++log.skipped_count;
    }
  }

  // Fills `m` from one data line; returns what is wrong with the line, or "" if nothing.
  std::string read_row(const csv::Line& line, bool last, std::vector<std::string_view>& fields, Measurement& m) {
    m.snr_db = prototype_.snr_db;
    m.has_snr = prototype_.has_snr;
    m.mode = prototype_.mode;
    m.valid = prototype_.valid;
    m.sensor = prototype_.sensor;
    const std::string truncated = last && !line.terminated ? "the last line looks truncated (no newline at the end of the file): " : "";
    if (csv::is_blank(line.text))
      return "empty line inside the data (expected " + std::to_string(field_count_) + " fields as in the header)";
    if (std::string why = csv::split_fields(line.text, fields); !why.empty()) return truncated + why;
    if (fields.size() != field_count_) {
      const std::string counts = "expected " + std::to_string(field_count_) + " fields as in the header (line " +
                                 std::to_string(header_number_) + "), got " + std::to_string(fields.size());
      if (last && fields.size() < field_count_)
        return "truncated last line: " + counts + (line.terminated ? "" : " (no newline at the end of the file)");
      return "wrong number of fields: " + counts;
    }

    std::string problem;
    auto complain = [&](const std::string& what, const Column& c) {
      problem = what + " (column " + c.name + ", value '" + token(fields[c.index]) + "')";
    };
    // An empty or half-written cell on an unterminated last line is most likely a cut-off write.
    auto real = [&](const Column& c, double& v) {
      switch (csv::parse_real(fields[c.index], v)) {
        case csv::CellStatus::Ok: return true;
        case csv::CellStatus::Empty: complain(truncated + "empty value where a number is expected", c); return false;
        case csv::CellStatus::NotFinite: complain("NaN or infinite value", c); return false;
        case csv::CellStatus::Malformed: complain(truncated + "not a number", c); return false;
      }
      return false;
    };

    double t = 0.0;
    if (!real(time_, t)) return problem;
    t *= time_scale_;
    if (has_previous_ && t < previous_time_) {
      complain("time goes backwards: earlier than " + token(previous_time_text_) + " on line " +
                   std::to_string(previous_line_),
               time_);
      return problem;
    }
    m.time = t;
    for (int k = 0; k < 3; ++k) {
      double v = 0.0;
      if (!real(value_[k], v)) return problem;
      m.value(k) = v * scale_[k];
      // Finite in the file's unit is not enough: 1e306 km is infinite in metres.
      if (!std::isfinite(m.value(k))) {
        complain("value overflows when converted to SI", value_[k]);
        return problem;
      }
    }
    if (m.frame == Frame::Spherical) {
      if (m.value(0) < 0.0) {
        complain("negative range", value_[0]);
        return problem;
      }
      if (std::fabs(m.value(2)) > std::numbers::pi / 2 * (1 + 1e-12)) {
        complain("elevation beyond +-90 deg", value_[2]);
        return problem;
      }
      m.value(1) = wrap_angle(m.value(1));
    }
    if (range_rate_.read()) {
      double v = 0.0;
      if (!real(range_rate_, v)) return problem;
      m.value(3) = v * rdot_scale_;
      if (!std::isfinite(m.value(3))) {
        complain("value overflows when converted to SI", range_rate_);
        return problem;
      }
    }
    if (snr_.read()) {
      if (!real(snr_, m.snr_db)) return problem;
      m.has_snr = true;
    }
    if (mode_.read()) {
      const std::string_view mode = fields[mode_.index];
      m.mode = csv::iequals(mode, "beacon") ? MeasMode::Beacon
               : csv::iequals(mode, "skin") ? MeasMode::Skin
                                             : MeasMode::Unknown;
    }
    if (valid_.read() && csv::parse_flag(fields[valid_.index], m.valid) != csv::CellStatus::Ok) {
      complain("not a validity flag (expected 1, 0, true or false)", valid_);
      return problem;
    }
    if (sensor_.read() && csv::parse_id(fields[sensor_.index], m.sensor) != csv::CellStatus::Ok) {
      complain("not a sensor id (expected a non-negative integer)", sensor_);
      return problem;
    }
    has_previous_ = true;
    previous_time_ = t;
    previous_time_text_ = fields[time_.index];
    previous_line_ = line.number;
    return {};
  }

  // Configuration.
  std::string node_;
  bool skip_bad_rows_ = false;
  std::string file_;
  Column time_, value_[3], range_rate_, snr_, mode_, valid_, sensor_;
  double time_scale_ = 1.0, scale_[3] = {1.0, 1.0, 1.0}, rdot_scale_ = 1.0;
  Measurement prototype_;
  std::size_t field_count_ = 0;
  int header_number_ = 1;

  // Parsing state (constructor only; the text views point into the file being read).
  bool has_previous_ = false;
  double previous_time_ = 0.0;
  std::string_view previous_time_text_;
  int previous_line_ = 0;

  // The replayed data.
  std::shared_ptr<const ParsedLog> log_;
  ParsedLog* building_ = nullptr;  // while this instance parses
  Measurement current_;            // the prototype with the fields of the row being emitted
  std::size_t cursor_ = 0;
  Frame frame_ = Frame::Spherical;
};

std::vector<ParamSpec> csv_params() {
  using P = ParamSpec;
  return {
      P::string("path", "CSV file; a relative path is relative to the pipeline file's folder").req(),
      P::choice<LogFrame>("frame", {{LogFrame::Spherical, "spherical"}, {LogFrame::Cartesian, "cartesian"}},
                          "what the rows hold: range/azimuth/elevation or x/y/z ENU")
          .def("spherical"),
      P::string("time_column", "column with the measurement time").def("time"),
      P::string("range_column", "spherical: column with the range").def("range"),
      P::string("azimuth_column", "spherical: column with the azimuth").def("azimuth"),
      P::string("elevation_column", "spherical: column with the elevation").def("elevation"),
      P::string("range_rate_column", "column with the range rate (length unit per second); read only if given"),
      P::string("x_column", "cartesian: column with x (east)").def("x"),
      P::string("y_column", "cartesian: column with y (north)").def("y"),
      P::string("z_column", "cartesian: column with z (up)").def("z"),
      P::string("snr_column", "column with the signal-to-noise ratio in dB; read only if given"),
      P::string("mode_column", "column with the track mode: beacon or skin (any case), anything else is unknown"),
      P::string("valid_column", "column with the validity flag: 1/0/true/false; invalid rows make filters coast"),
      P::string("sensor_column", "column with the sensor id (non-negative integer); overrides sensor_id"),
      P::choice<TimeUnit>("time_unit", {{TimeUnit::Second, "s"}, {TimeUnit::Millisecond, "ms"}}, "unit of the time column")
          .def("s"),
      length_unit_param("range_unit", "spherical: unit of range (and range rate per second)"),
      P::choice<AngleUnit>("angle_unit",
                           {{AngleUnit::Degree, "deg"}, {AngleUnit::Radian, "rad"}, {AngleUnit::Milliradian, "mrad"}},
                           "spherical: unit of azimuth and elevation")
          .def("deg"),
      length_unit_param("position_unit", "cartesian: unit of x, y, z (and range rate per second)"),
      P::real("sigma_range", dim::length, "spherical: range noise standard deviation").def("10 m").positive(),
      P::real("sigma_azimuth", dim::angle, "spherical: azimuth noise standard deviation").def("1 mrad").positive(),
      P::real("sigma_elevation", dim::angle, "spherical: elevation noise standard deviation").def("1 mrad").positive(),
      P::real("sigma_range_rate", dim::velocity, "range-rate noise standard deviation").def("1 m/s").positive(),
      P::real("sigma_position", dim::length, "cartesian: noise standard deviation of each of x, y, z")
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
          "problems. Each bad row (not a number, NaN/inf, wrong field count, negative range, time going backwards, "
          "truncated last line) is reported as FILE:LINE; with on_bad_row: skip it is left out and counted. "
          "Accepts CRLF line endings and double-quoted fields without embedded commas. Metrics: rows (data rows "
          "read), skipped_rows.";
  d.params = csv_params();
  d.min_inputs = 0;
  d.max_inputs = 0;
  d.produces = mask(ItemKind::Measurement);
  d.create = [](const Params& p) { return std::make_unique<CsvSource>(p); };
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("source.csv", trackflow::register_components)
