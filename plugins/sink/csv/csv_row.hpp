// Purpose: appends CSV cells to a reused string buffer: "%.*g" numbers, empty cells for missing or non-finite values.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>

namespace trackflow::csv {

class RowWriter {
 public:
  RowWriter(std::string& out, int precision) : out_(out), precision_(precision) {}

  void real(double v) {
    separate();
    if (!std::isfinite(v)) return;  // never "nan" or "inf" in the file
    char buf[40];
    const int n = std::snprintf(buf, sizeof buf, "%.*g", precision_, v);
    out_.append(buf, static_cast<size_t>(n));
  }
  void real_if(bool present, double v) {
    if (present)
      real(v);
    else
      empty();
  }
  void integer(std::uint64_t v) {
    separate();
    char buf[24];
    const int n = std::snprintf(buf, sizeof buf, "%llu", static_cast<unsigned long long>(v));
    out_.append(buf, static_cast<size_t>(n));
  }
  void text(std::string_view s) {
    separate();
    out_.append(s);
  }
  void empty() { separate(); }
  void end() {
    out_.push_back('\n');
    first_ = true;
  }

 private:
  void separate() {
    if (!first_) out_.push_back(',');
    first_ = false;
  }
  std::string& out_;
  int precision_;
  bool first_ = true;
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
