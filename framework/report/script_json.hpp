// Purpose: JSON text made safe to embed in an HTML <script> element: no '<', '>' or '&' left (each as its \u escape, the same JSON string).
#pragma once

#include <string>

namespace trackflow::report {

// Inside <script>, "</" could end the element and "<!--" switches the tokenizer to its "script
// data escaped" states, where a later "<script" swallows the rest of the page (HTML Living
// Standard §13.2.5.4-§13.2.5.27; §4.12.1.3 "Restrictions for contents of script elements"): a
// label "<!--<script>" once left the analyst a blank report (issue 27). Outside strings JSON has
// none of these characters, inside one "\u003c" is the same character (RFC 8259 §7), so every
// '<' becomes "\u003c" -- and '>' and '&' likewise, as is customary (no "-->", no entity).
inline std::string script_safe_json(const std::string& json) {
  std::string out;
  out.reserve(json.size() + json.size() / 16);
  for (char c : json) {
    if (c == '<')
      out += "\\u003c";
    else if (c == '>')
      out += "\\u003e";
    else if (c == '&')
      out += "\\u0026";
    else
      out += c;
  }
  return out;
}

}  // namespace trackflow::report
