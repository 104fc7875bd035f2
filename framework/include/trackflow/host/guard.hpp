// Purpose: naming the plugin, node and run when plugin code throws or crashes: per-thread activity records, the fatal-signal handler, internal errors.
#pragma once

#include <trackflow/component.hpp>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace trackflow::host {

// A bug (in trackflow or in a plugin), not a mistake of the analyst: the CLI exits 3.
class InternalError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The nodes of one graph instance as the crash handler prints them, built before anything runs
// (the handler may not allocate): "node 'kf' (filter.kalman from /x/tfplugin_filter_kalman.so)".
struct NodeLabels {
  std::vector<const Component*> components;
  std::vector<std::string> labels;
  // The label of `c`, or nullptr when `c` is none of these nodes.
  const std::string* find(const Component* c) const;
};

// What a thread is doing, read by the crash handler and by the engine when a plugin throws.
struct Activity {
  const char* doing = "";             // "run", "merging runs", "finishing", "building the graph", "loading"
  const NodeLabels* nodes = nullptr;  // the instance this thread drives, if any
  const std::string* subject = nullptr;  // e.g. the plugin file being loaded
  volatile std::uint64_t run = 0;
  volatile bool has_run = false;
};

// Makes `a` this thread's activity until destroyed (nests: the previous one comes back), and
// clears the executing node so that a stale mark from earlier work is never blamed.
class ActivityScope {
 public:
  explicit ActivityScope(Activity& a);
  ~ActivityScope();
  ActivityScope(const ActivityScope&) = delete;
  ActivityScope& operator=(const ActivityScope&) = delete;

 private:
  Activity* previous_;
  Component* previous_executing_;
};

// Sets the folder output_directory() returns on this thread until destroyed.
class OutputDirectoryScope {
 public:
  explicit OutputDirectoryScope(const std::string& dir);
  ~OutputDirectoryScope();
  OutputDirectoryScope(const OutputDirectoryScope&) = delete;
  OutputDirectoryScope& operator=(const OutputDirectoryScope&) = delete;

 private:
  const std::string* previous_;
};

// "node 'kf' (filter.kalman from /x.so) during run 3" for the component executing on this
// thread, or what the thread was doing when no node was executing.
std::string describe_activity();

// Turns whatever escaped a plugin call into the error the CLI reports: DataError and
// ConfigError keep their exit code 2 (prefixed with the run and node), everything else is an
// InternalError (exit 3) naming the plugin file, node and run. Call inside a catch block.
[[noreturn]] void rethrow_from_plugin();

// Fatal signals (SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT) print what was running -- the node,
// its plugin file and the run -- and exit 3 instead of dying by the signal; the first thread to
// crash reports, any other one crashing at the same time waits for its exit. exit(), std::exit
// and quick_exit called by plugin code (on a thread with an activity) are reported the same way.
// Installed by the CLI.
void install_crash_handler();
// An alternate signal stack for the calling thread, so that a stack overflow in a plugin is
// reported too. The engine calls it in each worker thread.
void prepare_thread_for_crash_reports();

}  // namespace trackflow::host
