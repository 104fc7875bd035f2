// Purpose: where a sink may write: under the run's output folder (--out), unless the user allowed more on the command line.
#pragma once

#include <boost/config.hpp>

#include <string>
#include <vector>

namespace trackflow {

// Why a sink's file name `path` would leave the output folder ("an absolute path", "'..' leaves
// the output folder"), or "" when it stays under it (or the user allowed more). A pipeline file
// from someone else must not be able to write anywhere else: check the name at construction
// and refuse it with Params::error.
BOOST_SYMBOL_VISIBLE std::string output_path_problem(const std::string& path);

// A sink declares, at construction, each file it will write beneath --out (its name relative
// to --out, as passed to SafeOutputFile::open_beneath), so that two outputs of one run naming
// one file (two sink.csv with one path; a sink's file equal to the report, a series file or
// --metrics-json) are refused at `validate` and before the runs instead of overwriting each
// other with exit 0 (issue 27). Outside the host's graph check it does nothing.
BOOST_SYMBOL_VISIBLE void declare_output_file(const std::string& node, const std::string& relative_path);

struct DeclaredOutput {
  std::string node;  // the node id
  std::string file;  // relative to --out, as declared
};
// The host: collects what declare_output_file is told on this thread while `into` is set
// (nullptr stops collecting).
BOOST_SYMBOL_VISIBLE void collect_declared_outputs(std::vector<DeclaredOutput>* into);

// The CLI's --allow-outside-out; off by default.
BOOST_SYMBOL_VISIBLE void allow_output_outside(bool allowed);
BOOST_SYMBOL_VISIBLE bool output_outside_allowed();

}  // namespace trackflow
