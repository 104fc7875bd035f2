// Purpose: streaming a CSV file line by line, field splitting and strict cell parsing (see csv_text.hpp).
#include "csv_text.hpp"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>

namespace trackflow::csv {
namespace {

bool blank_char(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

std::string_view trim(std::string_view s) {
  while (!s.empty() && blank_char(s.front())) s.remove_prefix(1);
  while (!s.empty() && blank_char(s.back())) s.remove_suffix(1);
  return s;
}

char lower(char c) { return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c; }

std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      // Case differences count half as much as other edits: "Range" is nearer "range" than "rage".
      const std::size_t sub = a[i - 1] == b[j - 1] ? 0 : lower(a[i - 1]) == lower(b[j - 1]) ? 1 : 2;
      cur[j] = std::min({prev[j] + 2, cur[j - 1] + 2, prev[j - 1] + sub});
    }
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

}  // namespace

LineStream::LineStream(std::size_t capacity)
    : buf_(new char[std::clamp(capacity, std::size_t{1}, kMaxLine)]), capacity_(std::clamp(capacity, std::size_t{1}, kMaxLine)) {}

void LineStream::open(int fd, std::uint64_t begin, std::uint64_t end, bool last_terminated, int first_number) {
  fd_ = fd;
  file_pos_ = begin;
  end_ = std::max(begin, end);
  last_terminated_ = last_terminated;
  number_ = first_number - 1;
  pos_ = len_ = 0;
}

bool LineStream::next(Line& line) {
  for (;;) {
    if (pos_ < len_)
      if (const void* nl = std::memchr(buf_.get() + pos_, '\n', len_ - pos_)) {
        const std::size_t at = static_cast<std::size_t>(static_cast<const char*>(nl) - buf_.get());
        line.text = std::string_view(buf_.get() + pos_, at - pos_);
        line.terminated = true;
        pos_ = at + 1;
        break;
      }
    if (file_pos_ >= end_) {
      if (pos_ >= len_) return false;
      // The range's last line: its break (if any) lies beyond `end`.
      line.text = std::string_view(buf_.get() + pos_, len_ - pos_);
      line.terminated = last_terminated_;
      pos_ = len_;
      break;
    }
    refill();
  }
  line.number = ++number_;
  if (!line.text.empty() && line.text.back() == '\r') line.text.remove_suffix(1);
  return true;
}

void LineStream::refill() {
  // The start of a line that continues beyond the buffer moves to its front.
  const std::size_t keep = len_ - pos_;
  if (pos_ > 0 && keep > 0) std::memmove(buf_.get(), buf_.get() + pos_, keep);
  pos_ = 0;
  len_ = keep;
  if (len_ == capacity_) {
    if (capacity_ >= kMaxLine)
      throw ReadError("line longer than 1 GiB (no log has such rows; is this a CSV log?)", number_ + 1);
    const std::size_t grown = std::min(2 * capacity_, kMaxLine);
    std::unique_ptr<char[]> bigger(new char[grown]);
    std::memcpy(bigger.get(), buf_.get(), len_);
    buf_ = std::move(bigger);
    capacity_ = grown;
  }
  const std::size_t want = static_cast<std::size_t>(std::min<std::uint64_t>(capacity_ - len_, end_ - file_pos_));
  ssize_t n;
  do n = ::pread(fd_, buf_.get() + len_, want, static_cast<off_t>(file_pos_));
  while (n < 0 && errno == EINTR);
  if (n < 0) throw ReadError(std::string("cannot read: ") + std::strerror(errno), 0);
  if (n == 0) throw ReadError("the file became shorter while it was read", 0);
  len_ += static_cast<std::size_t>(n);
  file_pos_ += static_cast<std::uint64_t>(n);
}

std::uint64_t content_end(int fd, std::uint64_t size) {
  char chunk[64 << 10];
  std::uint64_t next_break = size;  // the first line break after the bytes scanned so far
  for (std::uint64_t hi = size; hi > 0;) {
    const std::uint64_t lo = hi > sizeof chunk ? hi - sizeof chunk : 0;
    std::size_t got = 0;
    while (got < hi - lo) {
      const ssize_t n = ::pread(fd, chunk + got, static_cast<std::size_t>(hi - lo) - got, static_cast<off_t>(lo + got));
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) throw ReadError(std::string("cannot read: ") + std::strerror(errno), 0);
      if (n == 0) throw ReadError("the file became shorter while it was read", 0);
      got += static_cast<std::size_t>(n);
    }
    for (std::size_t i = static_cast<std::size_t>(hi - lo); i-- > 0;) {
      if (chunk[i] == '\n')
        next_break = lo + i;
      else if (!blank_char(chunk[i]))
        return next_break;
    }
    hi = lo;
  }
  return 0;
}

bool is_blank(std::string_view s) { return trim(s).empty(); }

std::string split_fields(std::string_view line, std::vector<std::string_view>& fields) {
  fields.clear();
  for (;;) {
    const auto comma = line.find(',');
    std::string_view f = trim(line.substr(0, comma));
    if (!f.empty() && f.front() == '"') {
      if (f.size() < 2 || f.back() != '"')
        return "field " + std::to_string(fields.size() + 1) +
               " opens a double quote that is not closed on this line (quoted fields may not contain commas or "
               "line breaks)";
      f = f.substr(1, f.size() - 2);
    }
    fields.push_back(f);
    if (comma == std::string_view::npos) return {};
    line.remove_prefix(comma + 1);
  }
}

CellStatus parse_real(std::string_view cell, double& value) {
  if (cell.empty()) return CellStatus::Empty;
  std::string_view digits = cell;
  if (digits.front() == '+') digits.remove_prefix(1);
  if (digits.empty() || digits.front() == '+' || (digits.front() == '-' && cell.front() == '+'))
    return CellStatus::Malformed;
  double v = 0.0;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), v);
  if (end != digits.data() + digits.size()) return CellStatus::Malformed;
  // from_chars reports out-of-range values (1e999) as an error without a value.
  if (ec == std::errc::result_out_of_range) return CellStatus::OutOfRange;
  if (ec != std::errc()) return CellStatus::Malformed;
  if (!std::isfinite(v)) return CellStatus::NotFinite;
  value = v;
  return CellStatus::Ok;
}

CellStatus parse_flag(std::string_view cell, bool& value) {
  if (cell.empty()) return CellStatus::Empty;
  if (cell == "1" || iequals(cell, "true")) {
    value = true;
    return CellStatus::Ok;
  }
  if (cell == "0" || iequals(cell, "false")) {
    value = false;
    return CellStatus::Ok;
  }
  return CellStatus::Malformed;
}

CellStatus parse_id(std::string_view cell, std::uint32_t& value) {
  if (cell.empty()) return CellStatus::Empty;
  unsigned long long v = 0;
  const auto [end, ec] = std::from_chars(cell.data(), cell.data() + cell.size(), v);
  if (ec != std::errc() || end != cell.data() + cell.size() || v > std::numeric_limits<std::uint32_t>::max())
    return CellStatus::Malformed;
  value = static_cast<std::uint32_t>(v);
  return CellStatus::Ok;
}

bool iequals(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) { return lower(x) == lower(y); });
}

std::string did_you_mean(std::string_view word, const std::vector<std::string>& candidates) {
  // The distance is quadratic in the lengths: long words are no typos (and a huge header line
  // must not cost minutes).
  if (word.size() > 64) return {};
  const std::string* best = nullptr;
  std::size_t best_d = std::numeric_limits<std::size_t>::max();
  for (const auto& c : candidates) {
    if (c.size() > 64) continue;
    const std::size_t d = edit_distance(word, c);
    if (d < best_d) {
      best_d = d;
      best = &c;
    }
  }
  // Distances are doubled (see edit_distance): a typo is at most a third of the word, at least 2 edits.
  const std::size_t limit = 2 * std::max<std::size_t>(2, word.size() / 3);
  if (!best || best_d > limit) return {};
  return " (did you mean '" + *best + "'?)";
}

}  // namespace trackflow::csv
