// Purpose: tests of pipeline parsing and parameter validation (positions, suggestions, units).
#include <trackflow/host/config.hpp>
#include <trackflow/host/validate.hpp>

#include <catch2/catch.hpp>

using namespace trackflow;
using namespace trackflow::host;

namespace {
std::vector<ParamSpec> specs() {
  return {ParamSpec::real("sigma_range", dim::length, "range noise").def("10 m").at_least(0),
          ParamSpec::real("rate", dim::frequency, "sample rate").req().positive(),
          ParamSpec::choice_words("mode", {"skin", "beacon"}, "track mode").def("skin"),
          ParamSpec::real_list("position", dim::length, "sensor position", 3).def("[0, 0, 0]")};
}
ConfigError validate_error(const std::string& yaml) {
  Value v = load_yaml_string(yaml, "p.yaml");
  try {
    validate_params(specs(), v, "radar", v.loc);
  } catch (const ConfigError& e) {
    return e;
  }
  FAIL("no error for: " << yaml);
  return ConfigError("");
}
}  // namespace

TEST_CASE("valid parameters come out in SI with defaults") {
  Value v = load_yaml_string("{ rate: 40 Hz, position: [1 km, 0, -2] }", "p.yaml");
  Params p = validate_params(specs(), v, "radar", v.loc);
  CHECK(p.real("rate") == 40.0);
  CHECK(p.real("sigma_range") == 10.0);
  CHECK_FALSE(p.given("sigma_range"));
  CHECK(p.given("rate"));
  CHECK(p.choice_word("mode") == "skin");
  CHECK(p.vec3("position")(0) == 1000.0);
}

TEST_CASE("parameter errors name line/column/node") {
  auto e = validate_error("rate: 40 Hz\nsigma_rnge: 3 m\n");
  CHECK(e.message().find("p.yaml:2:1") != std::string::npos);
  CHECK(e.message().find("node 'radar'") != std::string::npos);
  CHECK(e.message().find("did you mean 'sigma_range'") != std::string::npos);

  e = validate_error("rate: 40 Hz\nsigma_range: 3 mrad\n");
  CHECK(e.message().find("p.yaml:2:14") != std::string::npos);
  CHECK(e.message().find("dimension m") != std::string::npos);

  e = validate_error("sigma_range: 3 m\n");
  CHECK(e.message().find("missing required parameter 'rate'") != std::string::npos);

  e = validate_error("rate: fast\n");
  CHECK(e.message().find("not a number") != std::string::npos);

  e = validate_error("rate: 40 Hz\nmode: skn\n");
  CHECK(e.message().find("did you mean 'skin'") != std::string::npos);

  e = validate_error("rate: 40 Hz\nposition: [1, 2]\n");
  CHECK(e.message().find("expects 3 values") != std::string::npos);

  e = validate_error("rate: -1 Hz\n");
  CHECK(e.message().find("must be > 0, got '-1 Hz'") != std::string::npos);
}

TEST_CASE("pipeline structure errors") {
  auto err = [](const std::string& yaml) -> std::string {
    try {
      parse_pipeline(load_yaml_string(yaml, "p.yaml"), "p.yaml");
    } catch (const ConfigError& e) {
      return e.message();
    }
    return "no error";
  };
  CHECK(err("pipeline: {name: a}\nnodes:\n  - {id: a, type: x}\n  - {id: a, type: y}\n").find("duplicate node id 'a'") !=
        std::string::npos);
  CHECK(err("pipeline: {name: a}\nnodes: []\n").find("non-empty") != std::string::npos);
  CHECK(err("pipeline: {name: a}\nnode:\n  - {id: a, type: x}\n").find("did you mean 'nodes'") != std::string::npos);
  CHECK(err("pipeline: {name: a}\nnodes:\n  - {id: a, type: x, inptu: b}\n").find("p.yaml:3:") != std::string::npos);
  CHECK(err("pipeline: {name: a, runs: many}\nnodes:\n  - {id: a, type: x}\n").find("whole number") != std::string::npos);
}

TEST_CASE("overrides from the command line replace or add parameters") {
  Value v = load_yaml_string("pipeline: {name: a}\nnodes:\n  - id: kf\n    type: filter.kalman\n    params: { q: 1 }\n",
                             "p.yaml");
  auto cfg = parse_pipeline(v, "p.yaml", {parse_override("kf.q=4"), parse_override("kf.r=\"20 m\"")});
  CHECK(cfg.nodes[0].params.find("q")->scalar == "4");
  CHECK(cfg.nodes[0].params.find("r")->scalar == "20 m");
  CHECK_THROWS_WITH(parse_pipeline(v, "p.yaml", {parse_override("kff.q=4")}), Catch::Contains("did you mean 'kf'"));
  CHECK_THROWS_AS(parse_override("kfq4"), ConfigError);
}

TEST_CASE("a list of checks puts several checks on one metric") {
  const std::string head = "pipeline: {name: a}\nnodes:\n  - {id: s, type: sink.metrics}\nexpect:\n";
  auto cfg = parse_pipeline(
      load_yaml_string(head + "  s.position_rmse: [{ max: 5 }, { less_than: b.position_rmse }, { min: 1, max: 4 }]\n", "p.yaml"),
      "p.yaml");
  REQUIRE(cfg.expects.size() == 4);
  CHECK(cfg.expects[0].op == "max");
  CHECK(cfg.expects[0].value == 5.0);
  CHECK(cfg.expects[1].op == "less_than");
  CHECK(cfg.expects[1].ref_node == "b");
  CHECK(cfg.expects[2].op == "min");
  CHECK(cfg.expects[3].op == "max");
  for (const auto& e : cfg.expects) CHECK(e.metric == "position_rmse");
  CHECK_THROWS_WITH(parse_pipeline(load_yaml_string(head + "  s.anees: []\n", "p.yaml"), "p.yaml"),
                    Catch::Contains("empty list"));
  CHECK_THROWS_WITH(parse_pipeline(load_yaml_string(head + "  s.anees: [{ maxx: 1 }]\n", "p.yaml"), "p.yaml"),
                    Catch::Contains("did you mean 'max'"));
}

// The top-level sites: map becomes a list of records with the site's name first, located where
// the analyst wrote them; pipeline.frame_origin must name one of them.
TEST_CASE("sites and frame_origin are parsed and checked") {
  const std::string nodes = "nodes:\n  - {id: a, type: x}\n";
  const std::string sites =
      "sites:\n  naro: { latitude: 34.43 deg, longitude: 127.53 deg }\n  jeju: { latitude: 33.28 deg, longitude: "
      "126.46 deg, height: 100 m }\n";
  auto cfg = parse_pipeline(load_yaml_string("pipeline: {name: a, frame_origin: jeju}\n" + sites + nodes, "p.yaml"),
                            "p.yaml");
  REQUIRE(cfg.sites.items.size() == 2);
  CHECK(cfg.sites.items[1].entries.front().first == "name");
  CHECK(cfg.sites.items[1].entries.front().second.scalar == "jeju");
  CHECK(cfg.sites.items[1].find("height")->scalar == "100 m");
  CHECK(cfg.sites.items[1].find("height")->loc.line == 4);
  CHECK(cfg.frame_origin.scalar == "jeju");
  auto err = [&](const std::string& yaml) -> std::string {
    try {
      parse_pipeline(load_yaml_string(yaml, "p.yaml"), "p.yaml");
    } catch (const ConfigError& e) {
      return e.message();
    }
    return "no error";
  };
  CHECK_THAT(err("pipeline: {name: a, frame_origin: jeu}\n" + sites + nodes),
             Catch::Contains("p.yaml:1:35: frame_origin 'jeu' is not a site (did you mean 'jeju'?); sites: naro, jeju"));
  CHECK_THAT(err("pipeline: {name: a, frame_origin: jeju}\n" + nodes), Catch::Contains("no 'sites:' section"));
  CHECK_THAT(err("pipeline: {name: a, frame_origin: naro}\nsites: [naro]\n" + nodes), Catch::Contains("'sites' must be a map"));
  CHECK_THAT(err("pipeline: {name: a, frame_origin: naro}\nsites: { naro: 34 }\n" + nodes), Catch::Contains("site 'naro' must be a map"));
  CHECK_THAT(err("pipeline: {name: a, frame_origin: naro}\nsites: { naro: { name: x, latitude: 1 } }\n" + nodes),
             Catch::Contains("remove 'name'"));
  CHECK_THAT(err("pipeline: {name: a}\n" + sites + nodes), Catch::Contains("'sites' needs 'frame_origin: <site>'"));
  CHECK(err("pipeline: {name: a, frame_origin: naro}\n" + sites + nodes) == "no error");
}

namespace {
// Two in-memory declarations the nested parameters may name: a filter and a sink.
struct NestedTypes {
  ComponentDecl filter, sink;
  ComponentTypes types;
  NestedTypes() {
    filter.type = "filter.test";
    filter.kind = ComponentKind::Filter;
    filter.params = specs();
    sink.type = "sink.test";
    sink.kind = ComponentKind::Sink;
    types = {&filter, &sink};
  }
};
std::vector<ParamSpec> nested_specs() {
  return {ParamSpec::component("inner", {ComponentKind::Filter}, "one filter").req(),
          ParamSpec::component_list("modes", {}, "filters").with_prefix("filter.").def("[]")};
}
}  // namespace

TEST_CASE("nested params are checked by their own type, in SI") {
  NestedTypes t;
  Value v = load_yaml_string("{ inner: { type: filter.test, rate: 2 kHz },\n"
                             "  modes: [ { type: filter.test, rate: 1 Hz, sigma_range: 1 km } ] }",
                             "p.yaml");
  Params p = validate_params(nested_specs(), v, "imm", v.loc, t.types);
  const NestedComponent& inner = p.component("inner");
  CHECK(inner.type == "filter.test");
  CHECK(inner.params.real("rate") == 2000.0);
  CHECK(inner.params.real("sigma_range") == 10.0);  // the nested type's own default
  REQUIRE(p.components("modes").size() == 1);
  CHECK(p.components("modes")[0].params.real("sigma_range") == 1000.0);
}

TEST_CASE("nested component errors point at the nested key") {
  NestedTypes t;
  auto error_of = [&](const std::string& yaml) {
    Value v = load_yaml_string(yaml, "p.yaml");
    try {
      validate_params(nested_specs(), v, "imm", v.loc, t.types);
    } catch (const ConfigError& e) {
      return e;
    }
    FAIL("no error for: " << yaml);
    return ConfigError("");
  };
  ConfigError e = error_of("inner:\n  type: filter.test\n  rate: 1 Hz\n  sigma_rnage: 1 m\n");
  CHECK(e.where().line == 4);
  CHECK(e.where().column == 3);
  CHECK_THAT(e.what(), Catch::Contains("did you mean 'sigma_range'"));
  e = error_of("inner: { type: filter.test, rate: 3 m }");
  CHECK(e.where().column == 35);  // the value "3 m"
  CHECK_THAT(e.what(), Catch::Contains("unit dimension"));
  e = error_of("inner: { type: sink.tset }");
  CHECK_THAT(e.what(), Catch::Contains("accepted (filter): filter.test"));
  e = error_of("inner: { type: filter.test, rate: 1 Hz }\nmodes: [ { type: sink.test } ]");
  CHECK(e.where().line == 2);
  CHECK_THAT(e.what(), Catch::Contains("not accepted here"));
}

// Issue 26: a bare angle in the analyst's file is refused, a bare angle in a declaration's default
// is the plugin author's SI; a value above the declared plausible magnitude is accepted with one
// warning naming its line, collected only while a collector is installed (the host's graph build).
TEST_CASE("bare angles and implausible values") {
  const std::vector<ParamSpec> angle_specs = {
      ParamSpec::real("sigma_azimuth", dim::angle, "azimuth noise").def("0.001").at_least(0).plausible_up_to(0.3, "too wide?"),
      ParamSpec::real("clutter_density", dim::length.pow(-1) * dim::angle.pow(-2), "per m rad^2").def("0")};
  Value bare = load_yaml_string("{ sigma_azimuth: 2 }", "p.yaml");
  try {
    validate_params(angle_specs, bare, "radar", bare.loc);
    FAIL("a bare angle was accepted");
  } catch (const ConfigError& e) {
    CHECK_THAT(e.message(), Catch::Contains("p.yaml:1:18: node 'radar': parameter 'sigma_azimuth' is an angle"));
    CHECK_THAT(e.message(), Catch::Contains("2 rad = 114.592 deg"));
  }
  Value defaults = load_yaml_string("{ clutter_density: 1e-6 }", "p.yaml");
  std::vector<std::string> warnings;
  auto* previous = trackflow::detail::install_setup_warnings(&warnings);
  Params p = validate_params(angle_specs, defaults, "radar", defaults.loc);
  CHECK(p.real("sigma_azimuth") == 0.001);  // the bare default, in rad
  CHECK(p.real("clutter_density") == 1e-6);  // a density per angle may be bare
  CHECK(warnings.empty());
  Value wide = load_yaml_string("{ sigma_azimuth: 0.5 rad }", "p.yaml");
  (void)validate_params(angle_specs, wide, "radar", wide.loc);
  (void)validate_params(angle_specs, wide, "radar", wide.loc);  // the same warning is kept once
  trackflow::detail::install_setup_warnings(previous);
  REQUIRE(warnings.size() == 1);
  CHECK(warnings[0] == "p.yaml:1:18: node 'radar': parameter 'sigma_azimuth' = '0.5 rad' is valid but implausible: too wide?");
  (void)validate_params(angle_specs, wide, "radar", wide.loc);  // no collector: not collected
  CHECK(warnings.size() == 1);
}
