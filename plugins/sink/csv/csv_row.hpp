// Purpose: assembles CSV rows in a stack buffer appended to a reused string once a row: numbers shortest round-trip (output::write_shortest, std::to_chars' text) or "%.*g" (number_text), empty cells for missing values, "nan"/"inf" (counted) for non-finite ones.
#pragma once

#include "output/shortest_double.hpp"

#include <trackflow/number_text.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>

namespace trackflow::csv {

class RowWriter {
 public:
  // `precision`: significant digits ("%.*g", 1 to 17), or kShortest: the shortest text that reads
  // back as exactly the same double (std::from_chars, strtod; lossless), byte for byte
  // std::to_chars' shortest form.
  static constexpr int kShortest = 0;

  RowWriter(std::string& out, int precision) : out_(out), precision_(precision) {}
  RowWriter(const RowWriter&) = delete;
  RowWriter& operator=(const RowWriter&) = delete;
  ~RowWriter() { flush(); }

  // A value that exists. Non-finite ones are written as they are ("nan", "inf", "-inf") -- an
  // empty cell means "no value", which a NaN is not -- and counted, so the sink can fail the run.
  void real(double v) {
    cell(kNumberRoom);
    if (!std::isfinite(v)) {
      put(std::isnan(v) ? "nan" : v > 0 ? "inf" : "-inf");
      if (non_finite_++ == 0) first_non_finite_ = column_;
      return;
    }
    at_ = precision_ == kShortest ? output::write_shortest(at_, v) : number_text::write_general(at_, v, precision_);
  }
  void real_if(bool present, double v) {
    if (present)
      real(v);
    else
      empty();
  }
  void integer(std::uint64_t v) {
    cell(number_text::kWriteRoom);
    at_ = number_text::write_unsigned(at_, v);
  }
  void text(std::string_view s) {
    if (s.size() > kLongText) {  // past the buffer: straight into the string
      cell(0);
      flush();
      out_.append(s);
      return;
    }
    cell(s.size());
    put(s);
  }
  void empty() { cell(0); }
  void end() {
    if (at_ == buf_ + sizeof buf_) flush();
    *at_++ = '\n';
    flush();
    first_ = true;
    column_ = 0;
  }
  // Non-finite values written so far, and the 0-based column of the first.
  int non_finite() const { return non_finite_; }
  int first_non_finite_column() const { return first_non_finite_; }

 private:
  static constexpr std::size_t kLongText = 256;
  // Room a number's writer needs after the separator.
  static constexpr std::size_t kNumberRoom = std::max(number_text::kWriteRoom, output::kShortestRoom);

  // A separator (unless first in the row) with room for `n` characters after it.
  void cell(std::size_t n) {
    if (static_cast<std::size_t>(buf_ + sizeof buf_ - at_) < n + 1) flush();
    if (!first_) {
      *at_++ = ',';
      ++column_;
    }
    first_ = false;
  }
  void put(std::string_view s) {
    std::memcpy(at_, s.data(), s.size());
    at_ += s.size();
  }
  // One append a row (or a buffer full), not one per cell.
  void flush() {
    out_.append(buf_, static_cast<std::size_t>(at_ - buf_));
    at_ = buf_;
  }

  std::string& out_;
  int precision_;
  bool first_ = true;
  int column_ = 0;
  int non_finite_ = 0;
  int first_non_finite_ = -1;
  char buf_[2048];
  char* at_ = buf_;
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
