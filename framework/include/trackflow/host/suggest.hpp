// Purpose: "did you mean" suggestions for misspelt names (parameters, types, node ids).
#pragma once

#include <string>
#include <vector>

namespace trackflow::host {

std::size_t edit_distance(const std::string& a, const std::string& b);
// " (did you mean 'x'?)" or "" when nothing is close.
std::string did_you_mean(const std::string& word, const std::vector<std::string>& candidates);
std::string join(const std::vector<std::string>& words, const std::string& sep = ", ");

}  // namespace trackflow::host
