// Purpose: benchmark: nanoseconds per number of the formatters sink.csv could use (snprintf, std::to_chars through number_text, sink.csv's output::write_shortest, and {fmt}'s front end when built with it) on a million tracking-sized doubles, and whether their texts agree.
//
// Usage: trackflow-bench-number-format [--rounds R]
// The values: positions of a few km to tens of km, velocities of tens to hundreds of m/s, sigmas
// and NIS values spread over decades, all full-precision doubles as a filter writes them. The
// contenders take turns, best of R rounds (default 7) of CPU time each. Agreement: {fmt}'s
// "{:.10g}" against std::to_chars' (= snprintf's) "%.10g", {fmt}'s "{}" against to_chars' shortest
// (where they differ, e.g. in the exponent or in choosing fixed or scientific notation: counted);
// output::write_shortest (plugins/lib/output: Dragonbox digits, std::to_chars' layout) against
// to_chars' shortest (must be 0).
#include "bench_common.hpp"

#include "output/shortest_double.hpp"

#include <trackflow/number_text.hpp>

#ifdef TRACKFLOW_BENCH_FMT
#include <fmt/compile.h>
#include <fmt/format.h>
#endif

#include <cstdio>
#include <cstring>
#include <functional>
#include <random>
#include <string>
#include <vector>

using namespace trackflow;

namespace {

std::vector<double> tracking_values(std::size_t n) {
  std::mt19937_64 gen(20);
  std::normal_distribution<double> position(8000.0, 6000.0), velocity(0.0, 150.0);
  std::lognormal_distribution<double> spread(0.5, 2.0);
  std::vector<double> v(n);
  for (std::size_t i = 0; i < n; ++i) {
    switch (i % 4) {
      case 0: v[i] = position(gen); break;
      case 1: v[i] = velocity(gen); break;
      default: v[i] = spread(gen); break;  // sigmas, NIS, NEES
    }
  }
  return v;
}

struct Contender {
  const char* name;
  std::function<char*(char*, double)> write;
  double best = 1e300;
};

}  // namespace

int main(int argc, char** argv) {
  int rounds = 7;
  for (int i = 1; i + 1 < argc; i += 2)
    if (!std::strcmp(argv[i], "--rounds")) rounds = std::max(1, std::atoi(argv[i + 1]));
  const std::vector<double> values = tracking_values(1000000);
  std::vector<Contender> contenders = {
      {"snprintf \"%.10g\"", [](char* p, double v) { return p + std::snprintf(p, 64, "%.10g", v); }},
      {"std::to_chars precision 10 (write_general)", [](char* p, double v) { return number_text::write_general(p, v, 10); }},
      {"std::to_chars shortest (write_shortest)", [](char* p, double v) { return number_text::write_shortest(p, v); }},
      {"output::write_shortest (sink.csv, Dragonbox)", [](char* p, double v) { return output::write_shortest(p, v); }},
#ifdef TRACKFLOW_BENCH_FMT
      {"fmt \"{:.10g}\" (FMT_COMPILE)", [](char* p, double v) { return fmt::format_to(p, FMT_COMPILE("{:.10g}"), v); }},
      {"fmt shortest \"{}\" (FMT_COMPILE)", [](char* p, double v) { return fmt::format_to(p, FMT_COMPILE("{}"), v); }},
#endif
  };
  char buf[64];
  std::size_t sink = 0;
  for (int round = 0; round < rounds; ++round)
    for (auto& c : contenders) {
      const double t0 = bench::cpu_seconds();
      for (double v : values) sink += static_cast<std::size_t>(c.write(buf, v) - buf);
      c.best = std::min(c.best, bench::cpu_seconds() - t0);
    }
  std::printf("%zu tracking-sized doubles, best of %d rounds (CPU time), 1 thread (%zu characters written)\n", values.size(),
              rounds, sink);
#ifdef TRACKFLOW_BENCH_FMT
  std::printf("{fmt} %d.%d.%d\n", FMT_VERSION / 10000, FMT_VERSION / 100 % 100, FMT_VERSION % 100);
#endif
  for (const auto& c : contenders)
    std::printf("  %-46s %7.1f ns per number\n", c.name, 1e9 * c.best / static_cast<double>(values.size()));
  std::size_t output_differs = 0;
  for (double v : values) {
    char a[64], b[64];
    const std::size_t n = static_cast<std::size_t>(number_text::write_shortest(a, v) - a);
    if (n != static_cast<std::size_t>(output::write_shortest(b, v) - b) || std::memcmp(a, b, n) != 0) ++output_differs;
  }
  std::printf("output::write_shortest texts differing from std::to_chars shortest: %zu of %zu\n", output_differs, values.size());
#ifdef TRACKFLOW_BENCH_FMT
  // Agreement, on these values and on awkward ones (exponents, integers, signed zero).
  std::vector<double> check = values;
  for (double v : {0.0, -0.0, 1.0, 100.0, 1e20, 1e-5, 1.5e-7, 5e-324, 1e300, 123456789012345680.0, 0.1}) check.push_back(v);
  std::size_t precision_differs = 0, shortest_differs = 0;
  std::string example;
  char a[64], b[64];
  for (double v : check) {
    if (std::string(a, number_text::write_general(a, v, 10)) != std::string(b, fmt::format_to(b, FMT_COMPILE("{:.10g}"), v)))
      ++precision_differs;
    const std::string mine(a, number_text::write_shortest(a, v)), theirs(b, fmt::format_to(b, FMT_COMPILE("{}"), v));
    if (mine != theirs) {
      if (shortest_differs++ == 0) example = mine + " vs " + theirs;
    }
  }
  std::printf("texts differing from std::to_chars of %zu values: \"{:.10g}\" %zu, shortest \"{}\" %zu%s%s\n", check.size(),
              precision_differs, shortest_differs, example.empty() ? "" : ", e.g. ", example.c_str());
#endif
  return output_differs == 0 ? 0 : 1;
}
