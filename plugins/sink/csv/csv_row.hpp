// Purpose: appends CSV cells to a reused string buffer: "%.*g" numbers (std::to_chars), empty cells for missing values, "nan"/"inf" (counted) for non-finite ones.
#pragma once

#include <trackflow/number_text.hpp>

#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>

namespace trackflow::csv {

class RowWriter {
 public:
  RowWriter(std::string& out, int precision) : out_(out), precision_(precision) {}

  // A value that exists. Non-finite ones are written as they are ("nan", "inf", "-inf") -- an
  // empty cell means "no value", which a NaN is not -- and counted, so the sink can fail the run.
  void real(double v) {
    separate();
    if (!std::isfinite(v)) {
      out_.append(std::isnan(v) ? "nan" : v > 0 ? "inf" : "-inf");
      if (non_finite_++ == 0) first_non_finite_ = column_;
      return;
    }
    number_text::append_general(out_, v, precision_);
  }
  void real_if(bool present, double v) {
    if (present)
      real(v);
    else
      empty();
  }
  void integer(std::uint64_t v) {
    separate();
    number_text::append_unsigned(out_, v);
  }
  void text(std::string_view s) {
    separate();
    out_.append(s);
  }
  void empty() { separate(); }
  void end() {
    out_.push_back('\n');
    first_ = true;
    column_ = 0;
  }
  // Non-finite values written so far, and the 0-based column of the first.
  int non_finite() const { return non_finite_; }
  int first_non_finite_column() const { return first_non_finite_; }

 private:
  void separate() {
    if (!first_) out_.push_back(',');
    if (!first_) ++column_;
    first_ = false;
  }
  std::string& out_;
  int precision_;
  bool first_ = true;
  int column_ = 0;
  int non_finite_ = 0;
  int first_non_finite_ = -1;
};

// A field quoted per RFC 4180 when it holds a separator, a quote or a line break.
inline std::string quoted(const std::string& s) {
  if (s.find_first_of(",\"\r\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) {
    if (c == '"') q.push_back('"');
    q.push_back(c);
  }
  return q + "\"";
}

}  // namespace trackflow::csv
