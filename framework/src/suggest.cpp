// Purpose: edit-distance suggestions for misspelt names.
#include <trackflow/host/suggest.hpp>

#include <algorithm>

namespace trackflow::host {

std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t sub = prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, sub});
    }
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

std::string did_you_mean(const std::string& word, const std::vector<std::string>& candidates) {
  // Edit distance is quadratic in the lengths: a long word is not a typo of a name.
  if (word.size() > 64) return {};
  // Letter case costs nothing first (filter.UKF is filter.ukf, not filter.ekf: issue 26), the exact
  // distance breaks ties.
  auto lower = [](std::string x) {
    for (char& ch : x)
      if (ch >= 'A' && ch <= 'Z') ch = static_cast<char>(ch - 'A' + 'a');
    return x;
  };
  const std::string word_lower = lower(word);
  std::string best;
  std::size_t best_d = std::string::npos, best_exact = std::string::npos;
  for (const auto& c : candidates) {
    if (c.size() > 64) continue;
    const std::size_t d = edit_distance(word_lower, lower(c)), exact = edit_distance(word, c);
    if (d < best_d || (d == best_d && exact < best_exact)) {
      best_d = d;
      best_exact = exact;
      best = c;
    }
  }
  // Close enough to be a typo: a third of the word, at least 2 edits.
  const std::size_t limit = std::max<std::size_t>(2, word.size() / 3);
  if (best.empty() || best_d > limit) return {};
  return " (did you mean '" + quote_token(best) + "'?)";
}

std::string join(const std::vector<std::string>& words, const std::string& sep) {
  std::string s;
  for (const auto& w : words) s += (s.empty() ? "" : sep) + w;
  return s;
}

}  // namespace trackflow::host

namespace trackflow::host {

std::string join_some(const std::vector<std::string>& words, std::size_t max) {
  if (words.size() <= max) return join(words);
  std::vector<std::string> head(words.begin(), words.begin() + static_cast<std::ptrdiff_t>(max));
  return join(head) + ", ... (" + std::to_string(words.size() - max) + " more)";
}

std::string printable(std::string_view text) {
  std::string s;
  const std::size_t n = text.size();
  s.reserve(n);
  for (std::size_t i = 0; i < n;) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c < 0x80) {
      s += c < 0x20 || c == 0x7f ? '?' : static_cast<char>(c);
      ++i;
      continue;
    }
    // A whole, valid UTF-8 sequence is kept; any other byte becomes '?' (the message stays
    // valid UTF-8 for terminals and JSON). C1 controls (U+0080..U+009F, 0xC2 0x80..0x9F) are
    // escapes to some terminals too (CSI is U+009B): '?' as well.
    const std::size_t len = c >= 0xF0 && c <= 0xF4 ? 4 : c >= 0xE0 ? 3 : c >= 0xC2 && c <= 0xDF ? 2 : 0;
    bool ok = len > 0 && len <= 4 && i + len <= n;
    for (std::size_t k = 1; ok && k < len; ++k) ok = (static_cast<unsigned char>(text[i + k]) & 0xC0) == 0x80;
    if (ok && c == 0xC2 && static_cast<unsigned char>(text[i + 1]) < 0xA0) ok = false;
    if (ok) {
      s.append(text.substr(i, len));
      i += len;
    } else {
      s += '?';
      ++i;
    }
  }
  return s;
}

std::string quote_token(std::string_view word, std::size_t max) {
  // A sequence cut at `max` is incomplete, so it becomes '?' like any other broken one.
  std::string s = printable(word.substr(0, std::min(word.size(), max)));
  if (word.size() > max) s += "...";
  return s;
}

}  // namespace trackflow::host
