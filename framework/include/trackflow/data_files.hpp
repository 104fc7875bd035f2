// Purpose: a component names the data files it reads (a recorded log), so that the host can check that every process of an MPI job reads the same ones (size and content hash).
#pragma once

#include <boost/config.hpp>

#include <string>
#include <vector>

namespace trackflow {

// Called by a component when it opens a data file (source.csv for its log), with the path it
// opened. The processes of an MPI job compare each named file's size and content hash before any
// run: a different log at the same path on one rank would otherwise be merged silently (issue 27).
// Thread-safe; a path named twice is kept once.
BOOST_SYMBOL_VISIBLE void note_data_file(const std::string& path);

namespace detail {
// The host's side: every path named so far in this process, in the order first named.
BOOST_SYMBOL_VISIBLE std::vector<std::string> noted_data_files();
}  // namespace detail

}  // namespace trackflow
