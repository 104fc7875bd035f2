// Purpose: what each thread is doing, for messages when plugin code throws, and the fatal-signal handler that names the node.
#include <trackflow/error.hpp>
#include <trackflow/host/guard.hpp>

#include <cxxabi.h>
#include <signal.h>
#include <unistd.h>

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

const char* signal_name(int sig) {
  switch (sig) {
    case SIGSEGV: return "SIGSEGV, invalid memory access";
    case SIGBUS: return "SIGBUS, bus error";
    case SIGFPE: return "SIGFPE, arithmetic fault";
    case SIGILL: return "SIGILL, illegal instruction";
    case SIGABRT: return "SIGABRT, abort";
  }
  return "fatal signal";
}

void on_fatal_signal(int sig) {
  say("\ntrackflow: internal error: crash (");
  say(signal_name(sig));
  say(")");
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
  } catch (const ConfigError&) {
    throw;
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
  // On the alternate stack (a stack overflow leaves no room on the normal one); a fault inside
  // the handler itself falls back to the default action.
  sa.sa_flags = SA_ONSTACK | SA_RESETHAND;
  for (int sig : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT}) ::sigaction(sig, &sa, nullptr);
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
