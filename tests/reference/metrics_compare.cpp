// Purpose: compares a pipeline's --metrics-json with the one stored before a change of contract: same nodes, metrics, units and bands; values byte-identical, or within a stated relative tolerance.
//
// Usage: tf_metrics_compare EXPECTED.json ACTUAL.json [REL_TOL]
// Exit 0 when every value matches; 1 listing each difference by node and metric (at most 20 lines);
// 2 on unreadable input. REL_TOL (default 0) admits |a-b| <= REL_TOL*max(|a|,|b|): a changed contract
// may round differently, and the commit that needs it states why (see tests/reference/metrics/README.md).
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <string>

namespace {

using nlohmann::json;

json load(const char* path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(std::string("cannot read ") + path);
  return json::parse(in);
}

struct Comparison {
  double rel_tol = 0.0;
  int differences = 0;
  int exact_mismatch = 0;  // values equal within tolerance but not to the bit

  void report(const std::string& where, const std::string& what) {
    if (++differences <= 20) std::cout << where << ": " << what << "\n";
  }

  // Numbers: equal bits (NaN is written as null, so nulls compare structurally), else the tolerance.
  void number(const std::string& where, double expected, double actual) {
    if (expected == actual) return;
    const double scale = std::max(std::abs(expected), std::abs(actual));
    if (std::abs(expected - actual) <= rel_tol * scale) {
      ++exact_mismatch;
      return;
    }
    char buf[160];
    std::snprintf(buf, sizeof buf, "expected %.17g, got %.17g (relative %.3g)", expected, actual,
                  std::abs(expected - actual) / scale);
    report(where, buf);
  }

  void walk(const std::string& where, const json& expected, const json& actual) {
    if (expected.is_number() && actual.is_number()) {
      number(where, expected.get<double>(), actual.get<double>());
      return;
    }
    if (expected.type() != actual.type()) {
      report(where, "expected " + expected.dump() + ", got " + actual.dump());
      return;
    }
    if (expected.is_object()) {
      for (auto it = expected.begin(); it != expected.end(); ++it) {
        if (!actual.contains(it.key()))
          report(where + "/" + it.key(), "missing");
        else
          walk(where + "/" + it.key(), it.value(), actual.at(it.key()));
      }
      for (auto it = actual.begin(); it != actual.end(); ++it)
        if (!expected.contains(it.key())) report(where + "/" + it.key(), "not in the stored metrics");
      return;
    }
    if (expected.is_array()) {
      if (expected.size() != actual.size()) {
        report(where, "expected " + std::to_string(expected.size()) + " entries, got " + std::to_string(actual.size()));
        return;
      }
      for (size_t i = 0; i < expected.size(); ++i) walk(where + "/" + std::to_string(i), expected[i], actual[i]);
      return;
    }
    if (expected != actual) report(where, "expected " + expected.dump() + ", got " + actual.dump());
  }
};

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3 || argc > 4) {
    std::cerr << "usage: tf_metrics_compare EXPECTED.json ACTUAL.json [REL_TOL]\n";
    return 2;
  }
  Comparison c;
  try {
    if (argc == 4) c.rel_tol = std::stod(argv[3]);
    c.walk("", load(argv[1]), load(argv[2]));
  } catch (const std::exception& e) {
    std::cerr << "tf_metrics_compare: " << e.what() << "\n";
    return 2;
  }
  if (c.differences > 0) {
    std::cout << c.differences << " metric value(s) differ from " << argv[1] << "\n";
    return 1;
  }
  std::cout << "metrics equal to " << argv[1]
            << (c.exact_mismatch ? " within " + std::string(argv[3]) + " relative (" +
                                       std::to_string(c.exact_mismatch) + " not to the bit)"
                                 : std::string(" to the bit"))
            << "\n";
  return 0;
}
