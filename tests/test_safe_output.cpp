// Purpose: unit tests of SafeOutputFile (safe_output.hpp): no write through a symlink beneath the root, whole files or none, EFBIG reported, devices written in place.
#include <trackflow/safe_output.hpp>

#include <catch2/catch.hpp>

#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <csignal>
#include <cerrno>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace fs = std::filesystem;
using trackflow::SafeOutputFile;

namespace {

fs::path scratch(const std::string& name) {
  const fs::path p = fs::temp_directory_path() / ("tf_safe_output_" + std::to_string(::getpid())) / name;
  fs::remove_all(p);
  fs::create_directories(p);
  return p;
}

std::string slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

void put(const fs::path& p, const std::string& text) { std::ofstream(p, std::ios::binary) << text; }

// Entries of `dir` whose name ends in ".partial" (the temporaries).
int partials(const fs::path& dir) {
  int n = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    const std::string s = e.path().filename().string();
    n += s.size() > 8 && s.substr(s.size() - 8) == ".partial";
  }
  return n;
}

}  // namespace

TEST_CASE("a file beneath the root is renamed into place when whole") {
  const fs::path d = scratch("whole");
  SafeOutputFile f;
  REQUIRE(f.open_beneath(d.string(), "a/b/t.csv"));  // missing folders made
  REQUIRE(f.write("x,y\n"));
  CHECK_FALSE(fs::exists(d / "a/b/t.csv"));  // not under the real name before commit
  CHECK(partials(d) == 1);
  REQUIRE(f.commit());
  CHECK(slurp(d / "a/b/t.csv") == "x,y\n");
  CHECK(partials(d) == 0);
  CHECK(f.path() == (d / "a/b/t.csv").string());
}

TEST_CASE("a symlinked folder beneath the root is refused") {
  const fs::path d = scratch("linked");
  fs::create_directories(d / "out");
  fs::create_directories(d / "elsewhere");
  fs::create_directory_symlink("../elsewhere", d / "out/sub");
  SafeOutputFile f;
  CHECK_FALSE(f.open_beneath((d / "out").string(), "sub/t.csv"));
  CHECK(f.error_number() == ELOOP);
  CHECK(f.error().find("is a symbolic link") != std::string::npos);
  CHECK(fs::is_empty(d / "elsewhere"));
  // '..' inside the name does not climb through the link either: it is resolved lexically first.
  CHECK_FALSE(f.open_beneath((d / "out").string(), "sub/x/../t.csv"));
  CHECK(fs::is_empty(d / "elsewhere"));
  CHECK(trackflow::linked_folder_problem((d / "out").string(), "sub").find("symbolic link") != std::string::npos);
  CHECK(trackflow::linked_folder_problem(d.string(), "out/missing").empty());
}

TEST_CASE("links at the file's names are never written through") {
  const fs::path d = scratch("final_link");
  put(d / "victim", "precious\n");
  fs::create_symlink(d / "victim", d / "t.csv");
  fs::create_symlink(d / "victim", d / "t.csv.partial");
  SafeOutputFile f;
  REQUIRE(f.open_beneath(d.string(), "t.csv"));
  REQUIRE(f.write("new\n"));
  REQUIRE(f.commit());
  CHECK(slurp(d / "victim") == "precious\n");
  CHECK_FALSE(fs::is_symlink(d / "t.csv"));  // the rename replaced the link
  CHECK(slurp(d / "t.csv") == "new\n");
}

TEST_CASE("an abandoned file leaves no temporary behind") {
  const fs::path d = scratch("abandon");
  put(d / "t.csv", "earlier\n");
  {
    SafeOutputFile f;
    REQUIRE(f.open_beneath(d.string(), "t.csv"));
    REQUIRE(f.write("half"));
  }  // a run that threw: destroyed without commit
  CHECK(slurp(d / "t.csv") == "earlier\n");
  CHECK(partials(d) == 0);
}

TEST_CASE("two writers of one file each write their own temporary") {
  const fs::path d = scratch("two");
  SafeOutputFile a, b;
  REQUIRE(a.open_beneath(d.string(), "t.csv"));
  REQUIRE(b.open_beneath(d.string(), "t.csv"));
  CHECK(partials(d) == 2);
  REQUIRE(a.write(std::string(10000, 'a')));
  REQUIRE(b.write(std::string(20000, 'b')));
  REQUIRE(a.commit());
  REQUIRE(b.commit());
  CHECK(slurp(d / "t.csv") == std::string(20000, 'b'));
  CHECK(partials(d) == 0);
}

TEST_CASE("a write past RLIMIT_FSIZE fails with EFBIG") {
  const fs::path d = scratch("fsize");
  put(d / "t.csv", "earlier\n");
  struct rlimit old;
  REQUIRE(::getrlimit(RLIMIT_FSIZE, &old) == 0);
  auto* previous = std::signal(SIGXFSZ, SIG_IGN);
  struct rlimit small = old;
  small.rlim_cur = 4096;
  REQUIRE(::setrlimit(RLIMIT_FSIZE, &small) == 0);
  SafeOutputFile f;
  bool ok = f.open_beneath(d.string(), "t.csv");
  ok = ok && f.write(std::string(100000, 'x')) && f.commit();
  ::setrlimit(RLIMIT_FSIZE, &old);
  std::signal(SIGXFSZ, previous);
  CHECK_FALSE(ok);
  CHECK(f.error_number() == EFBIG);
  CHECK(f.error().find("File too large") != std::string::npos);
  CHECK(slurp(d / "t.csv") == "earlier\n");
  CHECK(partials(d) == 0);
}

TEST_CASE("command-line paths: devices in place and a pre-check") {
  SafeOutputFile f;
  REQUIRE(f.open_user_path("/dev/null"));
  REQUIRE(f.write("x"));
  REQUIRE(f.commit());
  struct stat st;
  REQUIRE(::stat("/dev/null", &st) == 0);
  CHECK(S_ISCHR(st.st_mode));
  const fs::path d = scratch("user");
  CHECK(trackflow::user_file_problem((d / "m.json").string()).empty());
  CHECK(fs::is_empty(d));  // the pre-check removes what it created
  CHECK_FALSE(trackflow::user_file_problem("/proc/nope.json").empty());
  trackflow::write_user_file((d / "m.json").string(), "{}\n");
  CHECK(slurp(d / "m.json") == "{}\n");
  CHECK(partials(d) == 0);
}
