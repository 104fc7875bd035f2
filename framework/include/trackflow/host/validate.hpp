// Purpose: checks a node's `params:` against its component's declaration and produces typed Params.
#pragma once

#include <trackflow/host/config.hpp>
#include <trackflow/params.hpp>
#include <trackflow/registry.hpp>

#include <string>
#include <vector>

namespace trackflow::host {

// The declarations a Component / ComponentList parameter may name (graph.cpp: every loaded type).
using ComponentTypes = std::vector<const ComponentDecl*>;

// Throws ConfigError (file:line:col, node id) on an unknown name (with a suggestion), a
// missing required parameter, a wrong type, a wrong unit dimension, or a value out of range.
Params validate_params(const std::vector<ParamSpec>& specs, const Value& given, const std::string& node,
                       const SourceLoc& node_loc, const ComponentTypes& types = {});

// Human-readable type of a declaration, e.g. "real [m]", "choice {a|b}".
std::string describe_type(const ParamSpec& s);

}  // namespace trackflow::host
