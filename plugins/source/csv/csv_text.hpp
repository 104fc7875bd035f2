// Purpose: splitting CSV text into numbered lines and fields, and strict parsing of numeric, boolean and integer cells.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace trackflow::csv {

struct Line {
  std::string_view text;    // without "\n" or "\r\n"
  int number = 0;           // 1-based, as an editor shows it
  bool terminated = true;   // false: the file ends inside this line (no final newline)
};

// Every line of `text`, in order. A file ending with "\n" has no extra empty last line.
std::vector<Line> split_lines(std::string_view text);

// The lines of `text` one at a time, as split_lines numbers them, without a table of them all.
// `text` must not end with a newline (cut it after the last line); `last_terminated` says
// whether that last line had one in the file.
class LineReader {
 public:
  LineReader(std::string_view text, bool last_terminated) : text_(text), last_terminated_(last_terminated) {}
  bool next(Line& line);
  bool done() const { return pos_ >= text_.size(); }

 private:
  std::string_view text_;
  bool last_terminated_;
  std::size_t pos_ = 0;
  int number_ = 0;
};

bool is_blank(std::string_view s);

// Splits at commas into `fields` (cleared first), trimming blanks and removing one pair of
// surrounding double quotes. Quoted fields may not contain commas; a field that opens a quote
// without closing it is reported. Returns an empty string when the line is well formed,
// otherwise what is wrong with it.
std::string split_fields(std::string_view line, std::vector<std::string_view>& fields);

enum class CellStatus { Ok, Empty, Malformed, NotFinite };

// The whole cell must be a decimal number ("12", "-3.5e2", "+4"); NaN and infinities are
// reported separately because they parse but must never reach a filter.
CellStatus parse_real(std::string_view cell, double& value);
// "1", "0", "true", "false" in any case.
CellStatus parse_flag(std::string_view cell, bool& value);
// A non-negative integer that fits 32 bits.
CellStatus parse_id(std::string_view cell, std::uint32_t& value);

bool iequals(std::string_view a, std::string_view b);

// " (did you mean 'x'?)" for the candidate closest to `word` when it is close enough to be a
// typo, else "".
std::string did_you_mean(std::string_view word, const std::vector<std::string>& candidates);

}  // namespace trackflow::csv
