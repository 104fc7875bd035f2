// Purpose: what the sinks scoring a tracker's track sets against truth share: their common parameters (statuses, skip_initial, dimensions), the statuses as a bit mask, and the check of their inputs.
#pragma once

#include <trackflow/component.hpp>
#include <trackflow/error.hpp>
#include <trackflow/params.hpp>
#include <trackflow/tracks.hpp>

#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

namespace trackflow::scoring {

// "confirmed, coasting" (commas, spaces or a YAML list's brackets between words) -> bit mask with
// bit TrackStatus set for each named status. "deleted" and unknown words are refused by name.
inline std::uint8_t parse_track_statuses(const Params& p, const std::string& name = "statuses") {
  std::string text = p.text(name);
  for (char& c : text)
    if (c == ',' || c == '[' || c == ']') c = ' ';
  std::istringstream is(text);
  std::uint8_t m = 0;
  for (std::string w; is >> w;) {
    if (w == "tentative") m |= 1u << static_cast<int>(TrackStatus::Tentative);
    else if (w == "confirmed") m |= 1u << static_cast<int>(TrackStatus::Confirmed);
    else if (w == "coasting") m |= 1u << static_cast<int>(TrackStatus::Coasting);
    else if (w == "deleted")
      throw p.error(name, "'deleted' cannot be scored: a deleted track is no estimate (give tentative, confirmed, coasting)");
    else
      throw p.error(name, "unknown status '" + w + "' (give some of tentative, confirmed, coasting)");
  }
  if (!m) throw p.error(name, "give at least one of tentative, confirmed, coasting");
  return m;
}

inline bool status_selected(std::uint8_t mask, TrackStatus s) { return (mask >> static_cast<int>(s)) & 1u; }

// The parameters every track-set sink declares after its own: which statuses, the transient left
// out, and planar or 3-D positions. Read them with parse_track_statuses, p.real("skip_initial")
// and planar_dimensions.
inline std::vector<ParamSpec> track_set_params() {
  return {
      ParamSpec::string("statuses", "track statuses scored, some of tentative, confirmed, coasting")
          .def("confirmed, coasting"),
      ParamSpec::real("skip_initial", dim::time, "leave out track sets earlier than the first one + this (transient)")
          .def("0 s")
          .at_least(0),
      ParamSpec::integer("dimensions", "3: x-y-z; 2: planar, x-y").def("3"),
  };
}

// true for dimensions: 2, false for 3; anything else is refused by name.
inline bool planar_dimensions(const Params& p) {
  const long long d = p.integer("dimensions");
  if (d != 2 && d != 3) throw p.error("dimensions", "must be 2 (planar, x-y) or 3, not " + std::to_string(d));
  return d == 2;
}

// One input of track sets (a tracker) and at least one of truth.
inline void check_track_set_inputs(const std::vector<InputInfo>& inputs, const std::string& type) {
  int tracks = 0, truths = 0;
  for (const auto& in : inputs) {
    tracks += (in.kinds & mask(ItemKind::Tracks)) ? 1 : 0;
    truths += (in.kinds & mask(ItemKind::Truth)) ? 1 : 0;
  }
  if (tracks != 1 || truths < 1)
    throw ConfigError(type + ": needs one input of track sets (a tracker) and truth, e.g. inputs: [tracker, "
                      "scenario]; got " + std::to_string(tracks) + " of tracks and " + std::to_string(truths) +
                      " of truth");
}

}  // namespace trackflow::scoring
