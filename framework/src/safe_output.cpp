// Purpose: the output files of safe_output.hpp: folders opened with O_NOFOLLOW beneath --out, a unique O_EXCL temporary, renameat after a checked write.
#include <trackflow/safe_output.hpp>

#include <trackflow/error.hpp>

#include <fcntl.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <system_error>
#include <vector>

namespace trackflow {
namespace fs = std::filesystem;

namespace {

// 64 unpredictable bits for the temporary's name (O_EXCL makes it safe anyway; the randomness
// only keeps another process from guessing and pre-creating it to make the run fail).
std::uint64_t random_bits() {
  static std::atomic<std::uint64_t> counter{0};
  std::uint64_t r = 0;
  if (::getrandom(&r, sizeof r, GRND_NONBLOCK) != static_cast<ssize_t>(sizeof r)) r = 0;
  const auto now = static_cast<std::uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count());
  return r ^ (now * 0x9E3779B97F4A7C15ull) ^ (++counter << 48);
}

std::string hex(std::uint64_t v) {
  static const char* d = "0123456789abcdef";
  std::string s(16, '0');
  for (int i = 15; i >= 0; --i, v >>= 4) s[static_cast<size_t>(i)] = d[v & 15];
  return s;
}

// The user's own folder, followed as given and created with its parents when missing.
int open_folder(const std::string& folder) {
  const std::string f = folder.empty() ? "." : folder;
  int fd = ::open(f.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0 && errno == ENOENT) {
    std::error_code ec;
    fs::create_directories(f, ec);
    fd = ::open(f.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  }
  return fd;
}

}  // namespace

SafeOutputFile::~SafeOutputFile() { abandon(); }

bool SafeOutputFile::fail(int err, const std::string& what) {
  errno_ = err ? err : EIO;
  error_ = "cannot write '" + shown_ + "': " + (what.empty() ? std::string(std::strerror(errno_)) : what);
  abandon();
  return false;
}

void SafeOutputFile::abandon() {
  if (file_) {
    std::fclose(file_);
    file_ = nullptr;
    if (!direct_ && dir_ >= 0 && !temp_.empty()) ::unlinkat(dir_, temp_.c_str(), 0);
  }
  if (dir_ >= 0) ::close(dir_);
  dir_ = -1;
}

bool SafeOutputFile::open_beneath(const std::string& root, const std::string& relative) {
  const fs::path rel = fs::path(relative).lexically_normal();
  shown_ = (fs::path(root.empty() ? "." : root) / relative).string();
  bool leaves = rel.has_root_path() || rel.empty();
  for (const auto& part : rel)
    if (part == "..") leaves = true;
  // Only with --allow-outside-out: the folder part is the user's explicit permission.
  if (leaves) return open_in((fs::path(root) / rel).parent_path().string(), {}, rel.filename().string());
  return open_in(root, rel.parent_path().string(), rel.filename().string());
}

bool SafeOutputFile::open_user_path(const std::string& path) {
  shown_ = path;
  const fs::path p(path);
  // An existing device, FIFO or socket (/dev/stdout, /dev/full): written in place, as the user
  // asked; renaming a file over it would replace it.
  struct stat st;
  if (::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode) && !S_ISDIR(st.st_mode)) {
    abandon();
    error_.clear();
    direct_ = true;
    const int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC | O_NOCTTY);
    if (fd < 0) return fail(errno, {});
    file_ = ::fdopen(fd, "wb");
    if (!file_) {
      const int err = errno;
      ::close(fd);
      return fail(err, {});
    }
    return true;
  }
  return open_in(p.parent_path().string(), {}, p.filename().string());
}

bool SafeOutputFile::open_in(const std::string& folder, const std::string& beneath, const std::string& name) {
  abandon();
  error_.clear();
  errno_ = 0;
  direct_ = false;
  name_ = name;
  if (name_.empty() || name_ == "." || name_ == "..") return fail(EISDIR, "it names a folder, not a file");
  dir_ = open_folder(folder);
  if (dir_ < 0) return fail(errno, "cannot open the folder '" + (folder.empty() ? std::string(".") : folder) + "': " +
                                       std::strerror(errno));
  // Each folder beneath: never a symlink (ELOOP with O_NOFOLLOW), made when missing.
  fs::path walked = folder.empty() ? fs::path(".") : fs::path(folder);
  for (const auto& part : fs::path(beneath)) {
    const std::string c = part.string();
    if (c.empty() || c == ".") continue;
    walked /= c;
    int next = ::openat(dir_, c.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    if (next < 0 && errno == ENOENT) {
      if (::mkdirat(dir_, c.c_str(), 0777) != 0 && errno != EEXIST)
        return fail(errno, "cannot create the folder '" + walked.string() + "': " + std::strerror(errno));
      next = ::openat(dir_, c.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    }
    if (next < 0) {
      const int err = errno;
      struct stat st;
      if (::fstatat(dir_, c.c_str(), &st, AT_SYMLINK_NOFOLLOW) == 0 && S_ISLNK(st.st_mode))
        return fail(ELOOP, "'" + walked.string() + "' is a symbolic link; files under --out are not written through links");
      return fail(err, "'" + walked.string() + "' is not a folder: " + std::strerror(err));
    }
    ::close(dir_);
    dir_ = next;
  }
  struct stat st;
  if (::fstatat(dir_, name_.c_str(), &st, AT_SYMLINK_NOFOLLOW) == 0 && S_ISDIR(st.st_mode))
    return fail(EISDIR, "it is a folder");
  // Short enough for NAME_MAX whatever the final name's length.
  const std::string stem = name_.size() > 120 ? name_.substr(0, 120) : name_;
  for (int attempt = 0; attempt < 16; ++attempt) {
    temp_ = "." + stem + "." + std::to_string(::getpid()) + "." + hex(random_bits()) + ".partial";
    const int fd = ::openat(dir_, temp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC | O_NOCTTY, 0666);
    if (fd < 0 && errno == EEXIST) continue;
    if (fd < 0) {
      const int err = errno;
      temp_.clear();
      return fail(err, {});
    }
    file_ = ::fdopen(fd, "wb");
    if (!file_) {
      const int err = errno;
      ::close(fd);
      ::unlinkat(dir_, temp_.c_str(), 0);
      temp_.clear();
      return fail(err, {});
    }
    return true;
  }
  temp_.clear();
  return fail(EEXIST, {});
}

bool SafeOutputFile::write(const char* data, std::size_t n) {
  if (!file_) return fail(EBADF, "not open");
  if (n && std::fwrite(data, 1, n, file_) != n) return fail(errno, {});
  return true;
}

bool SafeOutputFile::commit() {
  if (!file_) return fail(EBADF, "not open");
  if (std::fflush(file_) != 0 || std::ferror(file_)) return fail(errno, {});
  std::FILE* f = file_;
  file_ = nullptr;
  if (std::fclose(f) != 0) {
    const int err = errno;
    if (!direct_) ::unlinkat(dir_, temp_.c_str(), 0);
    return fail(err, {});
  }
  if (!direct_ && ::renameat(dir_, temp_.c_str(), dir_, name_.c_str()) != 0) {
    const int err = errno;
    ::unlinkat(dir_, temp_.c_str(), 0);
    return fail(err, {});
  }
  abandon();  // closes the folder
  return true;
}

void write_file_beneath(const std::string& root, const std::string& relative, std::string_view text) {
  SafeOutputFile f;
  if (!f.open_beneath(root, relative) || !f.write(text) || !f.commit()) throw ConfigError(f.error());
}

void write_user_file(const std::string& path, std::string_view text) {
  SafeOutputFile f;
  if (!f.open_user_path(path) || !f.write(text) || !f.commit()) throw ConfigError(f.error());
}

std::string user_file_problem(const std::string& path) {
  struct stat st;
  if (::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) return {};  // a device: written in place
  SafeOutputFile f;
  // Nothing is created in a missing folder by the check itself: the run creates it later.
  const fs::path parent = fs::path(path).parent_path();
  std::error_code ec;
  if (!parent.empty() && !fs::exists(parent, ec)) return {};
  if (!f.open_user_path(path)) return f.error();
  f.abandon();
  return {};
}

std::string linked_folder_problem(const std::string& root, const std::string& relative) {
  int dir = ::open(root.empty() ? "." : root.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir < 0) return {};
  fs::path walked = root.empty() || root == "." ? fs::path() : fs::path(root);  // "out", not "./out"
  std::string problem;
  for (const auto& part : fs::path(relative).lexically_normal()) {
    const std::string c = part.string();
    if (c.empty() || c == ".") continue;
    walked /= c;
    struct stat st;
    if (::fstatat(dir, c.c_str(), &st, AT_SYMLINK_NOFOLLOW) != 0) break;  // missing: made later
    if (S_ISLNK(st.st_mode)) {
      problem = "'" + walked.string() + "' is a symbolic link; trackflow does not write through links";
      break;
    }
    const int next = ::openat(dir, c.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    if (next < 0) {
      problem = "'" + walked.string() + "' is not a folder";
      break;
    }
    ::close(dir);
    dir = next;
  }
  ::close(dir);
  return problem;
}

}  // namespace trackflow
