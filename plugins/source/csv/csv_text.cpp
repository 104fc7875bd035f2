// Purpose: CSV line and field splitting and strict cell parsing (see csv_text.hpp).
#include "csv_text.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
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

std::vector<Line> split_lines(std::string_view text) {
  std::vector<Line> lines;
  lines.reserve(static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n')) + 1);
  int number = 1;
  while (!text.empty()) {
    const auto nl = text.find('\n');
    Line line;
    line.number = number++;
    line.terminated = nl != std::string_view::npos;
    line.text = text.substr(0, line.terminated ? nl : text.size());
    if (!line.text.empty() && line.text.back() == '\r') line.text.remove_suffix(1);
    lines.push_back(line);
    text.remove_prefix(line.terminated ? nl + 1 : text.size());
  }
  return lines;
}

bool LineReader::next(Line& line) {
  if (pos_ >= text_.size()) return false;
  const auto nl = text_.find('\n', pos_);
  line.number = ++number_;
  if (nl == std::string_view::npos) {
    line.text = text_.substr(pos_);
    line.terminated = last_terminated_;
    pos_ = text_.size();
  } else {
    line.text = text_.substr(pos_, nl - pos_);
    line.terminated = true;
    pos_ = nl + 1;
  }
  if (!line.text.empty() && line.text.back() == '\r') line.text.remove_suffix(1);
  return true;
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
  if (ec == std::errc::result_out_of_range) return CellStatus::NotFinite;
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
