// Purpose: CSV quoting, number cells and unit-carrying column names.
#include "csv_text.hpp"

#include <trackflow/number_text.hpp>

#include <cmath>

namespace trackflow::report {

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\r\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) {
    if (c == '"') q.push_back('"');
    q.push_back(c);
  }
  return q + "\"";
}

std::string csv_number(double v, int digits) {
  if (!std::isfinite(v)) return {};
  return number_text::general(v, digits);
}

std::string unit_suffix(const std::string& unit) {
  if (unit.empty() || unit == "1") return {};
  std::string out;
  for (size_t i = 0; i < unit.size(); ++i) {
    const char c = unit[i];
    if (c == '/') {
      if (out.empty() || out == "1")
        out = "per_";
      else
        out += "_per_";
    } else if (c == '^' || c == ' ') {
      continue;
    } else if (c == '*' || c == '.') {
      out += '_';
    } else {
      out += c;
    }
  }
  return out;
}

std::string column_header(const std::string& name, const std::string& unit) {
  const std::string s = unit_suffix(unit);
  return s.empty() ? name : name + "_" + s;
}

}  // namespace trackflow::report
