// Purpose: reading a CSV file line by line through a bounded buffer, splitting lines into fields, and strict parsing of numeric, boolean and integer cells.
#pragma once

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace trackflow::csv {

struct Line {
  std::string_view text;    // without "\n" or "\r\n"
  int number = 0;           // 1-based, as an editor shows it
  bool terminated = true;   // false: the file ends inside this line (no final newline)
};

// The lines of the bytes [begin, end) of an open file, numbered from `first_number` as an editor
// shows them, read with pread through one buffer: memory is the longest line, not the file. As
// for a text cut after its last line, the range must not end with a newline; `last_terminated`
// says whether that last line had one in the file. Views returned by next() stay valid only
// until the following call. Several streams may read one descriptor at once (pread has no
// shared offset).
class LineStream {
 public:
  static constexpr std::size_t kDefaultCapacity = std::size_t{256} << 10;
  // A line longer than this is refused: no log has such rows, and the buffer must stay bounded.
  static constexpr std::size_t kMaxLine = std::size_t{1} << 30;

  // The buffer grows only for a line longer than `capacity`: give the longest line's length plus
  // its line break and it never allocates after construction.
  explicit LineStream(std::size_t capacity = kDefaultCapacity);
  void open(int fd, std::uint64_t begin, std::uint64_t end, bool last_terminated, int first_number);
  // The next line, or false at the end of the range; throws ReadError.
  bool next(Line& line);
  bool done() const { return pos_ >= len_ && file_pos_ >= end_; }
  // File offset of the next line.
  std::uint64_t offset() const { return file_pos_ - (len_ - pos_); }

 private:
  void refill();

  std::unique_ptr<char[]> buf_;
  std::size_t capacity_ = 0, pos_ = 0, len_ = 0;
  int fd_ = -1;
  std::uint64_t file_pos_ = 0, end_ = 0;
  bool last_terminated_ = true;
  int number_ = 0;
};

// What LineStream throws: an I/O error, a file that shrank while it was read, or a line too long
// to buffer (`line` > 0: its number).
struct ReadError : std::runtime_error {
  ReadError(const std::string& what, int line) : std::runtime_error(what), line(line) {}
  int line;
};

// Where the content of a file of `size` bytes ends: the offset of the line break after its last
// non-blank line (blank lines after it are no data), `size` if that line has none, 0 if the file
// is blank. Reads the file backward from its end in small chunks; throws ReadError.
std::uint64_t content_end(int fd, std::uint64_t size);

bool is_blank(std::string_view s);

// Splits at commas into `fields` (cleared first), trimming blanks and removing one pair of
// surrounding double quotes. Quoted fields may not contain commas; a field that opens a quote
// without closing it is reported. Returns an empty string when the line is well formed,
// otherwise what is wrong with it.
std::string split_fields(std::string_view line, std::vector<std::string_view>& fields);

// OutOfRange: a decimal number beyond a double's range (1e999, 1e-400): number_range.hpp says which end.
enum class CellStatus { Ok, Empty, Malformed, NotFinite, OutOfRange };

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
