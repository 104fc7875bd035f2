// Purpose: the rule for names that become file names, CSV columns, JSON keys and chart labels (node ids, IMM mode names), and the rule for registered type names.
#pragma once

#include <algorithm>
#include <string_view>

namespace trackflow {

// ASCII letters, digits, '_' and '-', 1 to 100 of them: such a name needs no quoting in a CSV
// header, a JSON key, a file name or an HTML label, and cannot carry a terminal escape, a line
// break or markup ("<!--" in a label once blanked the report page, issue 27).
inline constexpr std::size_t kMaxPlainName = 100;
inline bool plain_name_char(char c) {
  const unsigned char u = static_cast<unsigned char>(c);
  return (u >= 'a' && u <= 'z') || (u >= 'A' && u <= 'Z') || (u >= '0' && u <= '9') || c == '_' || c == '-';
}
inline bool is_plain_name(std::string_view s) {
  return !s.empty() && s.size() <= kMaxPlainName && std::all_of(s.begin(), s.end(), plain_name_char);
}
// For messages: what is_plain_name() accepts.
inline constexpr const char* kPlainNameRule = "1 to 100 ASCII letters, digits, '_' or '-'";

// A component type name ("filter.kalman", "test.misbehave"): plain names joined by single dots.
// It is listed by `trackflow plugins`, written in pipelines and in the report.
inline bool is_type_name(std::string_view s) {
  if (s.empty() || s.size() > kMaxPlainName || s.front() == '.' || s.back() == '.') return false;
  for (std::size_t i = 0; i < s.size(); ++i)
    if (!(plain_name_char(s[i]) || (s[i] == '.' && s[i + 1] != '.'))) return false;
  return true;
}
inline constexpr const char* kTypeNameRule = "1 to 100 ASCII letters, digits, '_', '-' and single inner '.'";

}  // namespace trackflow
