// Purpose: "did you mean" suggestions for misspelt names (parameters, types, node ids), and words from files made safe to quote.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace trackflow::host {

std::size_t edit_distance(const std::string& a, const std::string& b);
// " (did you mean 'x'?)" or "" when nothing is close.
std::string did_you_mean(const std::string& word, const std::vector<std::string>& candidates);
std::string join(const std::vector<std::string>& words, const std::string& sep = ", ");
// The first `max` words joined, then "... (N more)": a message stays readable with 10 000 nodes.
std::string join_some(const std::vector<std::string>& words, std::size_t max = 20);
// A word from an analyst's or another party's file as it may appear in a message: at most `max`
// bytes (then "..."), control characters as '?', so a message never carries more of a file
// than the offending token, nor terminal escapes.
std::string quote_token(std::string_view word, std::size_t max = 60);
// Text from a file (a pipeline's description, a sink's path, a label) as it may be printed to a
// terminal whole: control characters (C0, DEL, C1) and broken UTF-8 as '?', the rest unchanged,
// so it can neither send terminal escapes nor forge a line of the summary with a '\n'.
std::string printable(std::string_view text);

}  // namespace trackflow::host
