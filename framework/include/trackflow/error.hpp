// Purpose: source locations and the exception types that carry them (configuration vs data errors).
#pragma once

#include <stdexcept>
#include <string>

namespace trackflow {

// A place in an analyst's file: 1-based line and column, 0 when unknown.
struct SourceLoc {
  std::string file;
  int line = 0;
  int column = 0;

  std::string str() const {
    if (file.empty() && line == 0) return {};
    std::string s = file.empty() ? std::string("<input>") : file;
    if (line > 0) s += ":" + std::to_string(line) + ":" + std::to_string(column);
    return s;
  }
};

// Bad configuration: the pipeline cannot run as written. The CLI maps it to exit code 2.
class ConfigError : public std::runtime_error {
 public:
  ConfigError(const std::string& what, SourceLoc where = {}, std::string node = {})
      : std::runtime_error(what), where_(std::move(where)), node_(std::move(node)) {}
  const SourceLoc& where() const { return where_; }
  const std::string& node() const { return node_; }
  // "file:line:col: node 'kf': message"
  std::string message() const {
    std::string s;
    if (auto w = where_.str(); !w.empty()) s += w + ": ";
    if (!node_.empty()) s += "node '" + node_ + "': ";
    return s + what();
  }

 private:
  SourceLoc where_;
  std::string node_;
};

// Bad input data (a recorded log, a malformed row). Also exit code 2.
class DataError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace trackflow
