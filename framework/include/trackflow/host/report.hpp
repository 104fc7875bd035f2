// Purpose: checks a pipeline's `expect:` block and writes the run summary (terminal table, metrics JSON).
#pragma once

#include <trackflow/host/engine.hpp>

#include <ostream>
#include <string>
#include <vector>

namespace trackflow::host {

struct ExpectResult {
  ExpectConfig expect;
  bool passed = false;
  double value = 0.0;
  std::string text;  // "score.position_rmse = 12.3 <= 25"
};

// Throws ConfigError when an expect names a node or metric that does not exist (listing
// what does), since that is a mistake in the file, not a failed expectation.
std::vector<ExpectResult> check_expects(const Graph& g, const Outcome& out);

void print_summary(std::ostream& os, const Graph& g, const Outcome& out, unsigned threads,
                   const std::vector<ExpectResult>& expects);
// { "<node id>": { "<metric>": { "value": v, "unit": "m"[, "band_lo", "band_hi", "confidence"] }, ... } }
// for nodes with metrics; a value that is not finite is null.
void write_metrics_json(const std::string& path, const Outcome& out);

}  // namespace trackflow::host
