// Purpose: tests of sim.scenario.
#include <catch2/catch.hpp>
TEST_CASE("placeholder") {}
