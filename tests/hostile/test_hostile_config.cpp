// Purpose: unit tests of the hostile-input rules of the loader, units, expect parsing, quoting and output paths (issue 13).
#include <trackflow/host/config.hpp>
#include <trackflow/host/suggest.hpp>
#include <trackflow/host/sweep.hpp>
#include <trackflow/output_path.hpp>
#include <trackflow/units.hpp>

#include <catch2/catch.hpp>

#include <string>

using namespace trackflow;
using namespace trackflow::host;

namespace {

std::string config_error(const std::string& yaml) {
  try {
    parse_pipeline(load_yaml_string(yaml, "p.yaml"), "p.yaml");
  } catch (const ConfigError& e) {
    return e.message();
  }
  return "no error";
}

std::string unit_error(const std::string& text) {
  try {
    (void)parse_quantity(text);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "no error";
}

const std::string kNodes = "nodes:\n  - {id: s, type: x}\n";

std::vector<ExpectConfig> expects(const std::string& entry) {
  return parse_pipeline(load_yaml_string("pipeline: {name: a}\n" + kNodes + "expect:\n  s.m: " + entry + "\n", "p.yaml"),
                        "p.yaml")
      .expects;
}

}  // namespace

TEST_CASE("units are finite in SI and powers are bounded") {
  CHECK(parse_quantity("1e300 km").value == Approx(1e303));
  CHECK_THAT(unit_error("1e308 km"), Catch::Matchers::Contains("not a finite number in SI"));
  CHECK_THAT(unit_error("1 km400/km399"), Catch::Matchers::Contains("too large"));
  CHECK_THAT(unit_error("1 m2147483647*m2147483647"), Catch::Matchers::Contains("too large"));
  CHECK_THAT(unit_error("1 m99999999999999"), Catch::Matchers::Contains("too large"));
  // Twelve is allowed per factor, the total exponent at most 24.
  CHECK(parse_quantity("1 m12/s12").dimension.length == 12);
  CHECK_THAT(unit_error("1 m12*m12*m12"), Catch::Matchers::Contains("power beyond 24"));
  CHECK(parse_quantity("+5 m").value == 5);
  CHECK_THAT(unit_error("++5 m"), Catch::Matchers::Contains("not a number"));
  // A long run of '+' is refused without recursion.
  CHECK_THAT(unit_error(std::string(100000, '+') + "1"), Catch::Matchers::Contains("not a number"));
}

TEST_CASE("seeds use the full 64 bits and runs never wrap") {
  auto seed_of = [](const std::string& s) {
    return parse_pipeline(load_yaml_string("pipeline: {name: a, seed: " + s + "}\n" + kNodes, "p.yaml"), "p.yaml").seed;
  };
  CHECK(seed_of("18446744073709551615") == 18446744073709551615ull);
  CHECK(seed_of("9223372036854775808") == 9223372036854775808ull);
  CHECK_THAT(config_error("pipeline: {name: a, seed: 18446744073709551616}\n" + kNodes),
             Catch::Matchers::Contains("p.yaml:1:27: seed must be a whole number"));
  CHECK_THAT(config_error("pipeline: {name: a, runs: -1}\n" + kNodes), Catch::Matchers::Contains("runs must be"));
  CHECK_THAT(config_error("pipeline: {name: a, runs: +3}\n" + kNodes), Catch::Matchers::Contains("runs must be"));
  CHECK_THAT(config_error("pipeline: {name: a, runs: 0}\n" + kNodes), Catch::Matchers::Contains("at least 1"));
}

TEST_CASE("every operator of an expect entry is checked") {
  const auto e = expects("{ max: 30, min: 1, equals: 5, tolerance: 2 }");
  REQUIRE(e.size() == 3);
  CHECK(e[0].op == "min");
  CHECK(e[0].value == 1);
  CHECK(e[1].op == "max");
  CHECK(e[2].op == "equals");
  CHECK(e[2].tolerance == 2);
  const auto bands = expects("{ within_band: 0.95, greater_than: t.m }");
  REQUIRE(bands.size() == 2);
  CHECK(bands[1].ref_node == "t");
  const auto ratio = expects("{ ratio_to: t.m, min: 0.9, max: 1.1 }");
  REQUIRE(ratio.size() == 2);
  CHECK(ratio[0].op == "ratio_min");
  CHECK(ratio[1].op == "ratio_max");
}

TEST_CASE("malformed expect entries are configuration errors") {
  auto err = [](const std::string& entry) {
    return config_error("pipeline: {name: a}\n" + kNodes + "expect:\n  s.m: " + entry + "\n");
  };
  CHECK_THAT(err("{ max: 25abc }"), Catch::Matchers::Contains("'max' needs a finite number, got '25abc'"));
  CHECK_THAT(err("{ max: nan }"), Catch::Matchers::Contains("finite number"));
  CHECK_THAT(err("{ equals: 1, tolerance: abc }"), Catch::Matchers::Contains("'tolerance' needs a finite number"));
  CHECK_THAT(err("{ equals: 1, tolerance: -1 }"), Catch::Matchers::Contains("must not be negative"));
  CHECK_THAT(err("{ tolerance: 1 }"), Catch::Matchers::Contains("applies only to 'equals'"));
  CHECK_THAT(err("{ min: 1, max: 2, typo: 3 }"), Catch::Matchers::Contains("unknown key 'typo'"));
  CHECK_THAT(err("{ within_band: 95 }"), Catch::Matchers::Contains("confidence between 0 and 1"));
  CHECK_THAT(err("{ ratio_to: t.m, max: 2, equals: 1 }"), Catch::Matchers::Contains("cannot be combined with 'ratio_to'"));
  CHECK_THAT(err("{ ratio_to: t.m }"), Catch::Matchers::Contains("needs 'min' and/or 'max'"));
}

TEST_CASE("alias bombs and cycles are refused") {
  CHECK_THAT(config_error("pipeline: &a {name: x, description: *a}\n" + kNodes),
             Catch::Matchers::Contains("p.yaml:1:11: an alias refers to a node that contains it"));
  std::string bomb = "a: &a [x,x,x,x,x,x,x,x,x,x]\n";
  std::string prev = "a";
  for (char c : std::string("bcdefgh")) {
    bomb += std::string(1, c) + ": &" + c + " [";
    for (int i = 0; i < 10; ++i) bomb += (i ? ",*" : "*") + prev;
    bomb += "]\n";
    prev = std::string(1, c);
  }
  CHECK_THROWS_WITH(load_yaml_string(bomb, "p.yaml"), Catch::Matchers::Contains("expands to more than"));
  // Shared (not recursive) aliases within the budget are fine.
  const Value v = load_yaml_string("a: &a [1, 2]\nb: [*a, *a]\n", "p.yaml");
  CHECK(v.find("b")->items.size() == 2);
}

TEST_CASE("quoted tokens are short and printable UTF-8") {
  CHECK(quote_token("abc") == "abc");
  CHECK(quote_token("a\x1b[31mb") == "a?[31mb");
  CHECK(quote_token("k\xff\xfe" "f") == "k??f");
  CHECK(quote_token("\xc3\xa9t\xc3\xa9") == "\xc3\xa9t\xc3\xa9");
  CHECK(quote_token(std::string(1000, 'x')).size() == 63);
  CHECK(join_some({"a", "b", "c"}, 2) == "a, b, ... (1 more)");
}

TEST_CASE("sink paths stay under the output folder") {
  allow_output_outside(false);
  CHECK(output_path_problem("log.csv").empty());
  CHECK(output_path_problem("sub/dir/log.csv").empty());
  CHECK(output_path_problem("a/../b.csv").empty());
  CHECK_THAT(output_path_problem("/etc/cron.d/x"), Catch::Matchers::Contains("absolute path"));
  CHECK_THAT(output_path_problem("../x.csv"), Catch::Matchers::Contains("leaves the output folder"));
  CHECK_THAT(output_path_problem("a/../../x.csv"), Catch::Matchers::Contains("leaves the output folder"));
  allow_output_outside(true);
  CHECK(output_path_problem("/tmp/x.csv").empty());
  allow_output_outside(false);
}

TEST_CASE("sweep grids are bounded") {
  std::vector<SweepAxis> axes(2);
  for (auto& a : axes) {
    a.node = "n";
    a.param = "p";
    a.values.assign(101, "1");
  }
  CHECK_THROWS_WITH(sweep_grid(axes), Catch::Matchers::Contains("more than 10000 points"));
  axes[1].values.assign(99, "1");
  CHECK(sweep_grid(axes).size() == 101 * 99);
}
