// Purpose: the parameters every probabilistic associator declares alike (assoc.pda, assoc.jpda) — which detections go to the initiator, and the survival probability that switches existence (IPDA, JIPDA) on.
#pragma once

#include <trackflow/params.hpp>

#include <string>

namespace trackflow::association {

inline ParamSpec initiation_threshold_param() {
  return ParamSpec::real("initiation_threshold", Dimension{},
                         "a detection whose probability of being some track's is at most this goes to the initiator "
                         "(0: any detection in a gate starts no track)")
      .def("0")
      .at_least(0)
      .at_most(1);
}

// `method`: "IPDA" or "JIPDA"; `plain`: the associator without it, "PDA" or "JPDA".
inline ParamSpec survival_probability_param(const std::string& method, const std::string& plain) {
  return ParamSpec::real("survival_probability", Dimension{},
                         method + ": keep each track's existence probability, a target surviving from one look to the "
                                  "next with this probability (Markov chain one); for init.existence and "
                                  "delete.existence (default: " + plain + ", no existence)")
      .positive()
      .at_most(1);
}

}  // namespace trackflow::association
