// Purpose: what the fuzz harnesses share: a declaration of every parameter type and unit dimension, checked the way a pipeline's nodes are.
#pragma once

#include <trackflow/host/config.hpp>
#include <trackflow/host/validate.hpp>

#include <vector>

namespace trackflow::fuzz {

// One parameter of each kind a plugin can declare, with the dimensions whose units the
// analyst writes most (length, angle, rate, spectral density), and a record list.
inline const std::vector<ParamSpec>& all_kinds() {
  static const std::vector<ParamSpec> specs = [] {
    std::vector<ParamSpec> s = {
        ParamSpec::real("length", dim::length, "a length").def("10 m").at_least(0),
        ParamSpec::real("angle", dim::angle, "an angle").def("1 mrad"),
        ParamSpec::real("rate", dim::frequency, "a rate").positive(),
        ParamSpec::real("q", dim::accel_psd, "a spectral density").def("0 m2/s3"),
        ParamSpec::real("ratio", dim::none, "a plain number").at_least(-1).at_most(1),
        ParamSpec::integer("count", "an integer").def("3").at_least(0).at_most(1000),
        ParamSpec::boolean("flag", "a boolean").def("false"),
        ParamSpec::string("text", "a string"),
        ParamSpec::choice_words("mode", {"skin", "beacon"}, "a choice").def("skin"),
        ParamSpec::real_list("position", dim::length, "three lengths", 3).def("[0, 0, 0]"),
        ParamSpec::real_list("rates", dim::angular_rate, "any number of rates"),
    };
    s.push_back(ParamSpec::records("segments",
                                   {ParamSpec::choice_words("type", {"cv", "turn"}, "segment type").req(),
                                    ParamSpec::real("duration", dim::time, "how long").positive().req(),
                                    ParamSpec::real("turn_rate", dim::angular_rate, "turn rate")},
                                   "records"));
    return s;
  }();
  return specs;
}

// Validates every node's parameters against all_kinds(); only ConfigError may come out.
inline void validate_all(const host::PipelineConfig& cfg) {
  for (const auto& n : cfg.nodes) {
    try {
      (void)host::validate_params(all_kinds(), n.params, n.id, n.loc);
    } catch (const ConfigError&) {
    }
  }
}

}  // namespace trackflow::fuzz
