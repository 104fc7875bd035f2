// Purpose: convert-consistency — runs the converters' Monte Carlo consistency study through the built plugins and prints it as Markdown.
#include "fusion_study.hpp"

#include <trackflow/error.hpp>
#include <trackflow/host/config.hpp>
#include <trackflow/host/plugins.hpp>
#include <trackflow/host/validate.hpp>

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

using namespace trackflow;

namespace {
constexpr std::uint64_t kDefaultDraws = 100000;
constexpr std::uint64_t kDefaultSeed = 20240603;
constexpr std::uint64_t kFusionTrials = 2000;

int usage() {
  std::fprintf(stderr,
               "usage: convert-consistency [--draws N] [--seed S] [--fusion-trials T]\n"
               "Monte Carlo of convert.classical/debiased/unbiased/unbiased_modified at the two issue-3 geometries,\n"
               "then the NEES of n fused conversions of a static target; prints Markdown tables.\n"
               "plugins are searched in $TRACKFLOW_PLUGIN_PATH and <bin>/../lib/trackflow/plugins.\n");
  return 2;
}
}  // namespace

int main(int argc, char** argv) {
  std::uint64_t draws = kDefaultDraws, seed = kDefaultSeed, fusion_trials = kFusionTrials;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if ((a == "--draws" || a == "--seed" || a == "--fusion-trials") && i + 1 < argc) {
      char* end = nullptr;
      const unsigned long long v = std::strtoull(argv[++i], &end, 10);
      if (*end != '\0' || (a != "--seed" && v < 2)) return usage();
      (a == "--draws" ? draws : a == "--seed" ? seed : fusion_trials) = v;
    } else {
      return usage();
    }
  }
  try {
    host::PluginRegistry registry;
    registry.load_directories(host::default_plugin_dirs());
    const conversion::ComponentFactory make = [&](const std::string& type) {
      const host::RegisteredType* t = registry.find(type);
      if (!t) {
        std::string where;
        for (const auto& d : registry.searched()) where += " " + d;
        throw ConfigError("plugin type " + type + " not found; searched:" + where);
      }
      const host::Value none = host::load_yaml_string("{}", "convert-consistency");
      return registry.create(*t, host::validate_params(t->decl.params, none, "conv", none.loc));
    };
    std::vector<conversion::StudyRow> rows;
    std::string notes;
    for (const auto& g : conversion::standard_geometries()) {
      const auto part = conversion::run_study(make, conversion::study_converters(), g, draws, seed);
      rows.insert(rows.end(), part.begin(), part.end());
      char buf[256];
      std::snprintf(buf, sizeof buf, "- %s: az 40°, el 20° (north_clockwise), r·σ²/σ_r = %.3g\n", g.name.c_str(),
                    g.nonlinearity());
      notes += buf;
    }
    std::printf("%s\n%s\n%llu draws per geometry, seed %llu; the same draws feed every converter.\n",
                conversion::markdown_table(rows).c_str(), notes.c_str(), static_cast<unsigned long long>(draws),
                static_cast<unsigned long long>(seed));

    // Fusion: NEES/dim of the information-weighted mean of n conversions of a static target.
    std::vector<conversion::FusionRow> fusion;
    std::string fusion_notes;
    for (const auto& g : conversion::fusion_geometries()) {
      for (int n : {1, 10, 100})
        fusion.push_back(conversion::run_fusion_study(make, conversion::study_converters(), g, n, fusion_trials, seed));
      char buf[256];
      std::snprintf(buf, sizeof buf, "- %s: r·σ²/σ_r = %.3g\n", g.name.c_str(), g.nonlinearity());
      fusion_notes += buf;
    }
    std::printf("\n%s\n%s\n%llu trials per row, seed %llu.\n",
                conversion::fusion_markdown_table(conversion::study_converters(), fusion).c_str(), fusion_notes.c_str(),
                static_cast<unsigned long long>(fusion_trials), static_cast<unsigned long long>(seed));
    return 0;
  } catch (const ConfigError& e) {
    std::fprintf(stderr, "convert-consistency: %s\n", e.message().c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "convert-consistency: %s\n", e.what());
  }
  return 1;
}
