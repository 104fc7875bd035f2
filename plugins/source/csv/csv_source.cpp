// Purpose: source.csv — replays a recorded radar log (CSV with a header row) as Measurements, checking every row.
#include "csv_text.hpp"

#include <trackflow/geometry.hpp>
#include <trackflow/common_params.hpp>
#include <trackflow/plugin.hpp>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
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

std::string read_file(const Params& p, const fs::path& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw p.error("path", "'" + path.string() + "' is a directory, not a CSV file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw p.error("path", "cannot open '" + path.string() + "': " + std::strerror(errno));
  in.seekg(0, std::ios::end);
  const auto size = in.tellg();
  in.seekg(0, std::ios::beg);
  std::string text(size > 0 ? static_cast<std::size_t>(size) : 0, '\0');
  if (!in.read(text.data(), static_cast<std::streamsize>(text.size())))
    throw p.error("path", "cannot read '" + path.string() + "'");
  return text;
}

class CsvSource final : public Generator {
 public:
  explicit CsvSource(const Params& p) : node_(p.node()), skip_bad_rows_(p.choice<OnBadRow>("on_bad_row") == OnBadRow::Skip) {
    configure(p);
    const fs::path path = resolve_path(p);
    file_ = path.string();
    const std::string text = read_file(p, path);
    parse(text);
  }

  void start_run(const RunContext& ctx) override {
    cursor_ = 0;
    // Every instance parses the same file; only run 0 reports, so each bad row is counted once.
    if (ctx.run == 0 && ctx.diagnostics)
      for (const auto& message : skipped_) ctx.diagnostics->skip(node_, message);
  }

  FrameMask produced_frames() const override { return mask(frame_); }

  double next_time() const override {
    return cursor_ < items_.size() ? items_[cursor_].time : std::numeric_limits<double>::infinity();
  }

  void emit_next() override {
    if (cursor_ < items_.size()) out.emit(items_[cursor_++]);
  }

  void finish(Summary& s, const FinishContext&) override {
    s.metric("rows", static_cast<double>(rows_));
    s.metric("skipped_rows", static_cast<double>(skipped_.size()));
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
    std::string listing;
    for (const auto& n : names) listing += (listing.empty() ? "" : ", ") + ("'" + n + "'");
    for (Column* c : {&time_, &value_[0], &value_[1], &value_[2], &range_rate_, &snr_, &mode_, &valid_, &sensor_}) {
      if (c->name.empty()) continue;
      int found = -1, count = 0;
      for (std::size_t i = 0; i < names.size(); ++i)
        if (names[i] == c->name) {
          if (found < 0) found = static_cast<int>(i);
          ++count;
        }
      if (count == 0)
        fail(at(header_line.number) + "no column '" + c->name + "' (" + c->param + ") in the header" +
             csv::did_you_mean(c->name, names) + "; the header has " + std::to_string(names.size()) +
             " column(s): " + listing + "; if the file names it differently, set " + c->param);
      if (count > 1)
        fail(at(header_line.number) + "column '" + c->name + "' (" + c->param + ") appears " + std::to_string(count) +
             " times in the header; rename one so the source knows which to read");
      c->index = found;
    }
    field_count_ = names.size();
  }

  void parse(const std::string& text) {
    const std::vector<csv::Line> lines = csv::split_lines(text);
    std::size_t first = 0, end = lines.size();
    while (first < end && csv::is_blank(lines[first].text)) ++first;
    while (end > first && csv::is_blank(lines[end - 1].text)) --end;  // blank lines at the end are fine
    if (first == end) fail(file_ + ": the file is empty; expected a header row, then one row per measurement");

    const csv::Line& header_line = lines[first];
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
    if (first + 1 == end) fail(at(header_line.number) + "the file has a header but no data rows");

    items_.reserve(end - first - 1);
    for (std::size_t i = first + 1; i < end; ++i) {
      ++rows_;
      Measurement m = prototype_;
      std::string why = read_row(lines[i], i + 1 == end, fields, m);
      if (why.empty()) {
        items_.push_back(m);
        continue;
      }
      why = at(lines[i].number) + why;
      if (!skip_bad_rows_) fail(why);
      skipped_.push_back(std::move(why));
    }
  }

  // Fills `m` from one data line; returns what is wrong with the line, or "" if nothing.
  std::string read_row(const csv::Line& line, bool last, std::vector<std::string_view>& fields, Measurement& m) {
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
      problem = what + " (column " + c.name + ", value '" + std::string(fields[c.index]) + "')";
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
      complain("time goes backwards: earlier than " + std::string(previous_time_text_) + " on line " +
                   std::to_string(previous_line_),
               time_);
      return problem;
    }
    m.time = t;
    for (int k = 0; k < 3; ++k) {
      double v = 0.0;
      if (!real(value_[k], v)) return problem;
      m.value(k) = v * scale_[k];
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
  std::vector<Measurement> items_;
  std::vector<std::string> skipped_;
  std::size_t rows_ = 0;
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
