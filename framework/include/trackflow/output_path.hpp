// Purpose: where a sink may write: under the run's output folder (--out), unless the user allowed more on the command line.
#pragma once

#include <boost/config.hpp>

#include <string>

namespace trackflow {

// Why a sink's file name `path` would leave the output folder ("an absolute path", "'..' leaves
// the output folder"), or "" when it stays under it (or the user allowed more). A pipeline file
// from someone else must not be able to write anywhere else: check the name at construction
// and refuse it with Params::error.
BOOST_SYMBOL_VISIBLE std::string output_path_problem(const std::string& path);

// The CLI's --allow-outside-out; off by default.
BOOST_SYMBOL_VISIBLE void allow_output_outside(bool allowed);
BOOST_SYMBOL_VISIBLE bool output_outside_allowed();

}  // namespace trackflow
