// Purpose: parsing of quantities with units into SI values and dimensions.
#include <trackflow/units.hpp>

#include <trackflow/number_range.hpp>

#include <cctype>
#include <charconv>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace trackflow {
namespace {

struct BaseUnit {
  const char* name;
  double scale;
  Dimension dimension;
};

constexpr double kDeg = std::numbers::pi / 180.0;
const BaseUnit kUnits[] = {
    {"m", 1.0, dim::length},          {"km", 1e3, dim::length},       {"cm", 1e-2, dim::length},
    {"mm", 1e-3, dim::length},        {"um", 1e-6, dim::length},      {"nmi", 1852.0, dim::length},
    {"ft", 0.3048, dim::length},      {"s", 1.0, dim::time},          {"ms", 1e-3, dim::time},
    {"us", 1e-6, dim::time},          {"min", 60.0, dim::time},       {"h", 3600.0, dim::time},
    {"rad", 1.0, dim::angle},         {"mrad", 1e-3, dim::angle},     {"urad", 1e-6, dim::angle},
    {"µrad", 1e-6, dim::angle},       {"deg", kDeg, dim::angle},      {"arcmin", kDeg / 60, dim::angle},
    {"arcsec", kDeg / 3600, dim::angle}, {"Hz", 1.0, dim::frequency}, {"kHz", 1e3, dim::frequency},
    {"MHz", 1e6, dim::frequency},     {"GHz", 1e9, dim::frequency},   {"dB", 1.0, dim::decibel},
};

std::string trim(std::string_view s) {
  size_t a = 0, b = s.size();
  while (a < b && std::isspace(static_cast<unsigned char>(s[a]))) ++a;
  while (b > a && std::isspace(static_cast<unsigned char>(s[b - 1]))) --b;
  return std::string(s.substr(a, b - a));
}

// Powers beyond this are typing mistakes or attacks (m2147483647 would overflow the exponents).
constexpr int kMaxPower = 12;
constexpr int kMaxExponent = 24;

// A unit's word as quoted in a message: short, no control characters.
std::string token(std::string_view s) {
  std::string t;
  for (size_t i = 0; i < s.size() && i < 40; ++i) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    t += c < 0x20 || c == 0x7f ? '?' : static_cast<char>(c);
  }
  return s.size() > 40 ? t + "..." : t;
}

// One factor such as "m", "s2", "s^3", "km".
Unit parse_factor(const std::string& f) {
  size_t end = f.size();
  while (end > 0 && std::isdigit(static_cast<unsigned char>(f[end - 1]))) --end;
  std::string name = f.substr(0, end);
  int power = 1;
  if (end < f.size()) {
    const auto [ptr, ec] = std::from_chars(f.data() + end, f.data() + f.size(), power);
    if (ec != std::errc() || ptr != f.data() + f.size() || power > kMaxPower)
      throw std::invalid_argument("power of '" + token(f) + "' is too large (at most " + std::to_string(kMaxPower) + ")");
  }
  if (!name.empty() && name.back() == '^') name.pop_back();
  for (const auto& u : kUnits) {
    if (name == u.name) return {std::pow(u.scale, power), u.dimension.pow(power)};
  }
  std::string known;
  for (const auto& u : kUnits) known += std::string(known.empty() ? "" : " ") + u.name;
  throw std::invalid_argument("unknown unit '" + token(f) + "' (known: " + known + ", combined with / and powers, e.g. m/s2)");
}

}  // namespace

std::string Dimension::str() const {
  if (dimensionless()) return "1";
  std::string num, den;
  auto part = [&](const char* sym, int e) {
    if (e == 0) return;
    std::string& s = e > 0 ? num : den;
    if (!s.empty()) s += "*";
    s += sym;
    if (std::abs(e) != 1) s += std::to_string(std::abs(e));
  };
  part("m", length);
  part("rad", angle);
  part("dB", decibel);
  part("s", time);
  if (num.empty()) num = "1";
  return den.empty() ? num : num + "/" + den;
}

Unit parse_unit(std::string_view text) {
  const std::string s = trim(text);
  if (s.empty()) return {};
  Unit result;
  size_t pos = 0;
  bool divide = false;
  while (pos <= s.size()) {
    size_t next = s.find_first_of("/*", pos);
    std::string factor = trim(s.substr(pos, next == std::string::npos ? std::string::npos : next - pos));
    if (factor.empty()) throw std::invalid_argument("malformed unit '" + token(s) + "'");
    if (factor != "1") {
      Unit u = parse_factor(factor);
      if (divide) {
        result.scale /= u.scale;
        result.dimension = result.dimension * u.dimension.pow(-1);
      } else {
        result.scale *= u.scale;
        result.dimension = result.dimension * u.dimension;
      }
      const Dimension& d = result.dimension;
      for (int e : {d.length, d.time, d.angle, d.decibel})
        if (e > kMaxExponent || e < -kMaxExponent)
          throw std::invalid_argument("unit '" + token(s) + "' has a power beyond " + std::to_string(kMaxExponent));
      if (!std::isfinite(result.scale) || result.scale == 0.0)
        throw std::invalid_argument("unit '" + token(s) + "' overflows a double");
    }
    if (next == std::string::npos) break;
    divide = s[next] == '/';
    pos = next + 1;
  }
  return result;
}

Quantity parse_quantity(std::string_view text) {
  const std::string s = trim(text);
  if (s.empty()) throw std::invalid_argument("empty value");
  double v = 0.0;
  // from_chars rejects a leading '+': skip one (only one: "++1" stays an error).
  const char* first = s.data() + (s.size() > 1 && s[0] == '+' && s[1] != '-' && s[1] != '+' ? 1 : 0);
  const char* last = s.data() + s.size();
  auto [ptr, ec] = std::from_chars(first, last, v);
  if (ec == std::errc::result_out_of_range)  // a number, but beyond a double's range: say which end
    throw std::invalid_argument("'" + token(s) + "' " +
                                number_range::describe(number_range::classify(std::string_view(first, ptr - first))));
  if (ec != std::errc()) {
    throw std::invalid_argument("'" + token(s) + "' is not a number");
  }
  if (!std::isfinite(v)) throw std::invalid_argument("'" + token(s) + "' is not a finite number");
  Quantity q;
  const std::string rest = trim(std::string_view(ptr, static_cast<size_t>(last - ptr)));
  if (rest.empty()) {
    q.value = v;
    return q;
  }
  const Unit u = parse_unit(rest);
  q.value = v * u.scale;
  // Finite before and after the unit: "1e308 km" is infinite in SI.
  if (!std::isfinite(q.value))
    throw std::invalid_argument("'" + token(s) + "' is not a finite number in SI (" + token(rest) + " overflows it)");
  q.dimension = u.dimension;
  q.had_unit = true;
  return q;
}

}  // namespace trackflow
