// Purpose: every file trackflow writes (sinks' files under --out, report, series, --metrics-json, sweep --csv) created without following symlinks, through a unique temporary renamed into place after a checked write.
#pragma once

#include <boost/config.hpp>

#include <cstddef>
#include <cstdio>
#include <string>
#include <string_view>

namespace trackflow {

// One output file, written whole or not at all (issue 27).
//
// Beneath a folder (open_beneath: a sink's `path` under --out): the folder itself is taken as
// the user gave it (created with its parents if missing), but every folder of `relative` is
// opened with openat(O_NOFOLLOW | O_DIRECTORY) from the one before (made with mkdirat when
// missing), so a symlink a pipeline's repository ships inside --out (`out/x/sub -> ..`,
// `out/x/tracks.csv.partial -> ~/.bashrc`) is refused or replaced, never written through. The
// data go to `.<name>.<pid>.<random>.partial` created with O_CREAT | O_EXCL | O_NOFOLLOW in the
// final folder (two runs into one folder never share it) and renameat() puts it in place only
// after fflush and fclose succeeded: a full disk, RLIMIT_FSIZE (EFBIG; the CLI ignores
// SIGXFSZ) or a run that throws removes the temporary and leaves any earlier file under the
// real name as it was. A symlink at the final name is replaced by the rename, not followed.
//
// A path from the command line (open_user_path: --metrics-json, --report, sweep --csv): its
// folder is the user's own choice and is followed; the file goes through a temporary the same
// way, except that an existing target that is not a regular file (/dev/stdout, a FIFO,
// /dev/full) is written directly: renaming over a device would replace it.
//
// Not copyable; one object per file. Every failure returns false and leaves error() as
// "cannot write '<path>': <reason>", for the caller to throw with its node and location.
class BOOST_SYMBOL_VISIBLE SafeOutputFile {
 public:
  SafeOutputFile() = default;
  SafeOutputFile(const SafeOutputFile&) = delete;
  SafeOutputFile& operator=(const SafeOutputFile&) = delete;
  ~SafeOutputFile();  // not committed: the temporary is removed

  // `relative` lexically normalised; absolute or leaving `root` by '..' (only reachable with
  // --allow-outside-out) it is split: its folder followed as given, its file name as below.
  bool open_beneath(const std::string& root, const std::string& relative);
  bool open_user_path(const std::string& path);

  bool write(const char* data, std::size_t n);
  bool write(std::string_view s) { return write(s.data(), s.size()); }
  // Flushes, closes (both checked) and renames the temporary to the final name.
  bool commit();
  // Removes the temporary (also done by the destructor).
  void abandon();

  bool is_open() const { return file_ != nullptr; }
  const std::string& path() const { return shown_; }  // as it is printed: <root>/<relative>
  const std::string& error() const { return error_; }
  int error_number() const { return errno_; }

 private:
  bool open_in(const std::string& folder, const std::string& beneath, const std::string& name);
  bool fail(int err, const std::string& what);

  int dir_ = -1;          // the final folder
  std::FILE* file_ = nullptr;
  bool direct_ = false;   // written in place (a device or FIFO named on the command line)
  std::string name_, temp_, shown_, error_;
  int errno_ = 0;
};

// `text` as the whole content of a file (see SafeOutputFile); throws ConfigError(error()).
BOOST_SYMBOL_VISIBLE void write_file_beneath(const std::string& root, const std::string& relative, std::string_view text);
BOOST_SYMBOL_VISIBLE void write_user_file(const std::string& path, std::string_view text);

// The pre-check of a command-line output file: creates the temporary it would be written
// through and removes it again (so `/proc/nope.json` is refused before the runs, not after).
// "" when it can be written, else the reason (strerror text).
BOOST_SYMBOL_VISIBLE std::string user_file_problem(const std::string& path);

// The folders trackflow itself names beneath a trusted one (sweep's <--out>/sweep-<i>, the
// default --out out/<pipeline name> beneath the current folder) are not followed either: the
// first existing folder of `relative` beneath `root` that is a symbolic link (or not a folder),
// as "'<root>/<part>' is a symbolic link; ...", or "" (a missing folder is no problem: it is made
// later).
BOOST_SYMBOL_VISIBLE std::string linked_folder_problem(const std::string& root, const std::string& relative);

}  // namespace trackflow
