// Purpose: the chart library inlined into every report (Vega and Vega-Lite, third_party/vega), embedded at build time.
#pragma once

#include <string_view>

namespace trackflow::report {

std::string_view vega_js();
std::string_view vega_lite_js();

}  // namespace trackflow::report
