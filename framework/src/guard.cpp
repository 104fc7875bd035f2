// Purpose: what each thread is doing, for messages when plugin code throws, and the fatal-signal handler that names the node.
#include <trackflow/error.hpp>
#include <trackflow/host/guard.hpp>

#include <cxxabi.h>
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <new>
#include <typeinfo>

namespace trackflow::detail {
extern thread_local const std::string* output_dir;
}

namespace trackflow::host {
namespace {

thread_local Activity* tl_activity = nullptr;

std::string demangled(const char* name) {
  int status = 0;
  std::unique_ptr<char, void (*)(void*)> d(abi::__cxa_demangle(name, nullptr, nullptr, &status), std::free);
  return status == 0 && d ? std::string(d.get()) : std::string(name);
}

// Async-signal-safe output: write(2) only.
void say(const char* s) {
  if (!s) return;
  size_t n = std::strlen(s);
  while (n > 0) {
    const ssize_t w = ::write(STDERR_FILENO, s, n);
    if (w <= 0) return;
    s += w;
    n -= static_cast<size_t>(w);
  }
}
void say(const std::string* s) {
  if (s) say(s->c_str());
}
void say_number(std::uint64_t v) {
  char buf[24];
  int i = sizeof buf - 1;
  buf[i] = '\0';
  do {
    buf[--i] = static_cast<char>('0' + v % 10);
    v /= 10;
  } while (v > 0 && i > 0);
  say(buf + i);
}

// Set by the first thread that reports a fatal end (a signal, or exit() inside plugin code).
// Another thread that crashes at the same moment must neither print a second message nor die by
// its signal (the process would end by that signal instead of exit 3): it waits for the first
// one's _exit. Lock-free, so the handler stays async-signal-safe (POSIX.1-2017 XSH 2.4.3).
std::atomic<bool> g_reporting{false};
static_assert(std::atomic<bool>::is_always_lock_free);

[[noreturn]] void wait_for_the_first_report() {
  for (;;) ::pause();
}

// "trackflow: internal error: <what> in <node> during run N; a bug in ...", then _exit(3): what
// a crash and an exit() inside plugin code have in common. write(2) and _exit(2) only.
[[noreturn]] void report_fatal(const char* what) {
  if (g_reporting.exchange(true)) wait_for_the_first_report();
  say("\ntrackflow: internal error: ");
  say(what);
  const Activity* a = tl_activity;
  const std::string* node = a && a->nodes ? a->nodes->find(detail::executing) : nullptr;
  if (node) {
    say(" in ");
    say(node);
  } else if (a && a->subject) {
    say(" while ");
    say(a->doing);
    say(" ");
    say(a->subject);
  } else if (a) {
    say(" while ");
    say(a->doing);
  }
  if (a && a->has_run) {
    say(" during run ");
    say_number(a->run);
  }
  say(node || (a && a->subject) ? "; a bug in that plugin (or in trackflow)\n"
                                : "; a bug in trackflow or in a plugin it loaded\n");
  ::_exit(3);
}

void on_fatal_signal(int sig) {
  // Without SA_RESETHAND the signal stays blocked while this runs: a fault inside the handler
  // itself still ends the process by the default action (a blocked synchronous fault is fatal).
  switch (sig) {
    case SIGSEGV: report_fatal("crash (SIGSEGV, invalid memory access)");
    case SIGBUS: report_fatal("crash (SIGBUS, bus error)");
    case SIGFPE: report_fatal("crash (SIGFPE, arithmetic fault)");
    case SIGILL: report_fatal("crash (SIGILL, illegal instruction)");
    case SIGABRT: report_fatal("crash (SIGABRT, abort)");
  }
  report_fatal("crash (fatal signal)");
}

// exit(), std::exit or quick_exit called by plugin code: the engine's own exits happen on
// threads with no activity (main returns after every scope is gone). A plugin's exit(0) in a run
// would otherwise end trackflow with status 0, no summary and no outputs.
void on_exit_inside_plugin_code() {
  if (tl_activity) report_fatal("exit() called (the process was ended by plugin code)");
}

}  // namespace

const std::string* NodeLabels::find(const Component* c) const {
  if (!c) return nullptr;
  for (size_t i = 0; i < components.size() && i < labels.size(); ++i)
    if (components[i] == c) return &labels[i];
  return nullptr;
}

ActivityScope::ActivityScope(Activity& a) : previous_(tl_activity), previous_executing_(detail::executing) {
  tl_activity = &a;
  detail::executing = nullptr;
}
ActivityScope::~ActivityScope() {
  tl_activity = previous_;
  detail::executing = previous_executing_;
}

OutputDirectoryScope::OutputDirectoryScope(const std::string& dir) : previous_(detail::output_dir) {
  detail::output_dir = &dir;
}
OutputDirectoryScope::~OutputDirectoryScope() { detail::output_dir = previous_; }

std::string describe_activity() {
  const Activity* a = tl_activity;
  std::string s;
  if (const std::string* node = a && a->nodes ? a->nodes->find(detail::executing) : nullptr)
    s = *node;
  else if (a && a->subject)
    s = std::string("while ") + a->doing + " " + *a->subject;
  else if (a)
    s = std::string("while ") + a->doing;
  if (a && a->has_run) s += (s.empty() ? "" : " ") + std::string("during run ") + std::to_string(a->run);
  return s;
}

void rethrow_from_plugin() {
  const std::string where = describe_activity();
  const Activity* a = tl_activity;
  const std::string run = a && a->has_run ? "run " + std::to_string(a->run) + ": " : std::string();
  const std::string* node = a && a->nodes ? a->nodes->find(detail::executing) : nullptr;
  try {
    throw;
  } catch (const ConfigError& e) {
    // Thrown by a plugin during a run: which run, and which node when the error does not say.
    if (run.empty() && (!node || !e.node().empty())) throw;
    throw ConfigError(run + (node && e.node().empty() ? *node + ": " : std::string()) + e.what(), e.where(), e.node());
  } catch (const DataError& e) {
    // Bad input data: exit 2, with the run and the node that found it.
    throw DataError(run + (node ? *node + ": " : std::string()) + e.what());
  } catch (const InternalError&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw;
  } catch (const std::exception& e) {
    throw InternalError((where.empty() ? std::string("plugin code") : where) + " threw " + demangled(typeid(e).name()) +
                        ": " + e.what() + " (a bug in that plugin, not a problem with the pipeline)");
  } catch (...) {
    throw InternalError((where.empty() ? std::string("plugin code") : where) +
                        " threw an exception that is not a std::exception (a bug in that plugin)");
  }
}

void install_crash_handler() {
  prepare_thread_for_crash_reports();
  struct sigaction sa;
  std::memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_fatal_signal;
  sigemptyset(&sa.sa_mask);
  // On the alternate stack (a stack overflow leaves no room on the normal one). No SA_RESETHAND:
  // it resets the action for the whole process, so a second thread crashing at the same moment
  // died by its signal (14 of 30 runs with --threads 2, issue 27); report_fatal holds it instead.
  sa.sa_flags = SA_ONSTACK;
  for (int sig : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT}) ::sigaction(sig, &sa, nullptr);
  std::atexit(on_exit_inside_plugin_code);
  std::at_quick_exit(on_exit_inside_plugin_code);
}

void prepare_thread_for_crash_reports() {
  // Freed when the thread exits, after the alternate stack is switched off.
  constexpr size_t kSize = 64 * 1024;
  struct AltStack {
    std::unique_ptr<char[]> memory{new char[kSize]};
    AltStack() {
      stack_t st{};
      st.ss_sp = memory.get();
      st.ss_size = kSize;
      st.ss_flags = 0;
      ::sigaltstack(&st, nullptr);
    }
    ~AltStack() {
      stack_t st{};
      st.ss_flags = SS_DISABLE;
      ::sigaltstack(&st, nullptr);
    }
  };
  thread_local AltStack stack;
  (void)stack;
}

}  // namespace trackflow::host
