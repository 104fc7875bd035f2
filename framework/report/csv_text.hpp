// Purpose: CSV cells and headers that load without guessing: RFC 4180 quoting, numbers, units in column names.
#pragma once

#include <string>

namespace trackflow::report {

// A field quoted per RFC 4180 when it holds a separator, a quote or a line break (quotes doubled).
std::string csv_field(const std::string& s);

// "%.*g" with `digits` significant digits; empty for NaN or infinity (never "nan" in a file).
std::string csv_number(double v, int digits = 12);

// The unit as it goes into a column name: "m" -> "m", "m/s" -> "m_per_s", "m^2/s^3" and
// "m2/s3" -> "m2_per_s3", "1/s" -> "per_s", "" or "1" -> "".
std::string unit_suffix(const std::string& unit);

// "position_rmse" + "m" -> "position_rmse_m"; a pure number keeps its name.
std::string column_header(const std::string& name, const std::string& unit);

}  // namespace trackflow::report
