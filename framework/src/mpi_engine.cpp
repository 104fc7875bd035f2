// Purpose: the Monte Carlo ensemble across the processes of an MPI job (Open MPI through Boost.MPI): the MPI-ranks transport of the run dispatcher — rank 0 hands out runs, every process runs them on its threads, results come back as bytes.
#include <trackflow/data_files.hpp>
#include <trackflow/host/guard.hpp>
#include <trackflow/host/suggest.hpp>
#include <trackflow/number_text.hpp>
#include <trackflow/host/mpi.hpp>
#include <trackflow/rng.hpp>
#include <trackflow/run_result_codec.hpp>
#include <trackflow/version.hpp>

#include "mpi_launch.hpp"
#include "run_dispatcher.hpp"
#include "worker_pool.hpp"

#include <boost/mpi/collectives.hpp>
#include <boost/mpi/communicator.hpp>
#include <boost/mpi/environment.hpp>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <mutex>
#include <new>
#include <thread>

namespace trackflow::host {
namespace {

namespace mpi = boost::mpi;

// Point-to-point messages of one distributed run. Workers (ranks > 0) send kRequest (how many
// runs they can take) and get kAssign (run indices; none: stop); they send each run's kResult
// (the index, then the record's bytes) or kError (the index, then the failure), then kDone; rank 0 ends with kFinal (0 ok,
// 1 failed) to each once all are done, so every process leaves at the same point.
enum Tag : int { kRequest = 101, kAssign, kResult, kError, kDone, kFinal, kPayload, kIdentity };

// Raw MPI for the point-to-point messages (one MPI message per value, whatever Boost.MPI's
// version would make of strings and vectors). A byte string goes as its length (kResult or
// kError) followed by the bytes in chunks of at most 1 GiB (kPayload): a count is an int.
constexpr std::uint64_t kChunk = std::uint64_t{1} << 30;

void send_u64(MPI_Comm c, int dest, int tag, std::uint64_t v) { MPI_Send(&v, 1, MPI_UINT64_T, dest, tag, c); }
std::uint64_t recv_u64(MPI_Comm c, int src, int tag) {
  std::uint64_t v = 0;
  MPI_Recv(&v, 1, MPI_UINT64_T, src, tag, c, MPI_STATUS_IGNORE);
  return v;
}
void send_bytes(MPI_Comm c, int dest, int tag, const std::string& s) {
  send_u64(c, dest, tag, s.size());
  for (std::uint64_t at = 0; at < s.size(); at += kChunk) {
    const std::uint64_t n = std::min<std::uint64_t>(kChunk, s.size() - at);
    MPI_Send(s.data() + at, static_cast<int>(n), MPI_BYTE, dest, kPayload, c);
  }
}
std::string recv_bytes(MPI_Comm c, int src, int tag) {
  std::string s(recv_u64(c, src, tag), '\0');
  for (std::uint64_t at = 0; at < s.size(); at += kChunk) {
    const std::uint64_t n = std::min<std::uint64_t>(kChunk, s.size() - at);
    MPI_Recv(s.data() + at, static_cast<int>(n), MPI_BYTE, src, kPayload, c, MPI_STATUS_IGNORE);
  }
  return s;
}
void send_runs(MPI_Comm c, int dest, const std::vector<std::uint64_t>& runs) {
  MPI_Send(runs.data(), static_cast<int>(runs.size()), MPI_UINT64_T, dest, kAssign, c);
}

class Session final : public MpiSession {
 public:
  Session(int& argc, char**& argv) : env_(argc, argv, mpi::threading::funneled, false) {
    if (env_.thread_level() < mpi::threading::funneled)
      throw ConfigError("the MPI library does not support threads (MPI_THREAD_FUNNELED): trackflow needs it");
  }
  int rank() const override { return world_.rank(); }
  int size() const override { return world_.size(); }
  mpi::communicator& world() { return world_; }

  void agree_setup(bool ok, const std::string& error_message) override {
    const int all_ok = mpi::all_reduce(world_, ok ? 1 : 0, mpi::minimum<int>());
    if (all_ok) return;
    std::vector<std::string> messages;
    mpi::gather(world_, ok ? std::string() : error_message, messages, 0);
    if (world_.rank() != 0) throw ReportedElsewhere();
    if (!ok) return;  // rank 0's own failure: the caller rethrows it as it is
    for (int r = 1; r < world_.size(); ++r)
      if (!messages[static_cast<size_t>(r)].empty())
        throw ConfigError("rank " + std::to_string(r) + ": " + messages[static_cast<size_t>(r)]);
    throw ConfigError("a process failed to set up");
  }

  int agree_exit_code(int code) override { return mpi::all_reduce(world_, code, mpi::maximum<int>()); }

 private:
  mpi::environment env_;
  mpi::communicator world_;
};

// Checked on every process, whichever runs the run, so the job behaves the same for any -np.
void check_codecs(const Graph& g, const GraphInstance& inst, const RunRecord& rec) {
  for (size_t i = 0; i < g.nodes.size(); ++i)
    if (rec.results[i] && !dynamic_cast<const RunResultCodec*>(inst.components[i].get()))
      throw ConfigError("node '" + g.nodes[i].config.id + "' (" + g.nodes[i].config.type +
                        ") returns per-run results that cannot be sent between the processes of an MPI job: its "
                        "plugin does not implement trackflow::RunResultCodec (run_result_codec.hpp). Run this "
                        "pipeline without mpirun (--threads N uses one machine's cores).");
}

void save_record(const RunRecord& rec, std::uint64_t run, const GraphInstance& inst, std::string& out) {
  ByteWriter w(out);
  w.put(run);
  w.put(rec.source_items);
  w.put(rec.measurements_processed);
  for (const auto* list : {&rec.diagnostics.skips, &rec.diagnostics.warnings}) {
    w.put(static_cast<std::uint64_t>(list->size()));
    for (const auto& e : *list) {
      w.put_string(e.node);
      w.put_string(e.message);
    }
  }
  for (size_t i = 0; i < rec.results.size(); ++i) {
    w.put(static_cast<std::uint8_t>(rec.results[i] ? 1 : 0));
    if (rec.results[i]) dynamic_cast<const RunResultCodec&>(*inst.components[i]).save_run_result(*rec.results[i], w);
  }
}

RunRecord load_record(ByteReader& in, const GraphInstance& aggregate) {
  RunRecord rec;
  in.get(rec.source_items);
  in.get(rec.measurements_processed);
  for (auto* list : {&rec.diagnostics.skips, &rec.diagnostics.warnings}) {
    list->resize(in.get<std::uint64_t>());
    for (auto& e : *list) {
      e.node = in.get_string();
      e.message = in.get_string();
    }
  }
  rec.results.resize(aggregate.components.size());
  for (size_t i = 0; i < rec.results.size(); ++i)
    if (in.get<std::uint8_t>())
      rec.results[i] = dynamic_cast<const RunResultCodec&>(*aggregate.components[i]).load_run_result(in);
  if (!in.done()) throw DataError("a per-run result received from another process has trailing bytes");
  return rec;
}

// What the processes of one job must share for their runs to be interchangeable, item by item:
// the build, --seed, --runs, every node's type and every validated parameter value (after --set,
// defaults included, in SI: "0.5 km" and "500 m" agree), and each data file a component named
// (data_files.hpp) by its size and content. `shown` is what the refusal quotes (the value as
// written where there is one).
struct Identity {
  std::vector<std::string> names, texts, shown;
  void add(std::string name, std::string text, std::string as_shown = {}) {
    names.push_back(std::move(name));
    shown.push_back(as_shown.empty() ? text : std::move(as_shown));
    texts.push_back(std::move(text));
  }
};

// FNV-1a, 64 bit (Fowler, Noll, Vo; IETF draft-eastlake-fnv): a checksum, not a defence against
// a chosen collision (the ranks are one analyst's own processes).
struct Fnv {
  std::uint64_t h = 1469598103934665603ull;
  void mix(const void* data, std::size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
  }
  void mix(const std::string& s) { mix(s.data(), s.size() + 1); }  // with its '\0': "ab"+"c" != "a"+"bc"
};

std::string canonical(const Params& p);
std::string canonical(const ParamValue& v) {
  std::string s;
  switch (v.type) {
    case ParamType::Real: number_text::append_shortest(s, v.real); break;
    case ParamType::Integer: s = std::to_string(v.integer); break;
    case ParamType::Boolean: s = v.boolean ? "true" : "false"; break;
    case ParamType::String:
    case ParamType::Choice: s = v.text; break;
    case ParamType::RealList:
      s = "[";
      for (size_t i = 0; i < v.reals.size(); ++i) {
        if (i) s += ", ";
        number_text::append_shortest(s, v.reals[i]);
      }
      s += "]";
      break;
    case ParamType::Records:
    case ParamType::Component:
    case ParamType::ComponentList:
      s = "[";
      for (size_t i = 0; i < v.records.size(); ++i) s += (i ? ", " : "") + canonical(v.records[i]);
      for (size_t i = 0; i < v.components.size(); ++i)
        s += (i || !v.records.empty() ? ", {type: " : "{type: ") + v.components[i].type +
             (v.components[i].params.values().empty() ? "}" : ", " + canonical(v.components[i].params).substr(1));
      s += "]";
      break;
  }
  return s;
}
std::string canonical(const Params& p) {
  std::string s = "{";
  for (size_t i = 0; i < p.values().size(); ++i)
    s += (i ? ", " : "") + p.values()[i].first + ": " + canonical(p.values()[i].second);
  return s + "}";
}

// "12345 bytes, FNV-1a 0123456789abcdef", or why it could not be read (never throws: every rank
// must reach the comparison, or the others would wait for it forever).
std::string file_identity(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return std::string("cannot be read: ") + std::strerror(errno);
  Fnv h;
  std::uint64_t size = 0;
  std::vector<char> buf(1 << 20);
  for (std::size_t n; (n = std::fread(buf.data(), 1, buf.size(), f)) > 0;) {
    h.mix(buf.data(), n);
    size += n;
  }
  const bool failed = std::ferror(f) != 0;
  std::fclose(f);
  if (failed) return "cannot be read to its end";
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h.h));
  return std::to_string(size) + " bytes, FNV-1a " + hex;
}

Identity identity_of(const Graph& g, const RunOptions& opt) {
  Identity id;
  const std::uint16_t one = 1;
  id.add("trackflow build", "ABI " + std::to_string(kAbiVersion) + ", SDK " + kSdkVersion + ", Estimate " +
                                std::to_string(sizeof(Estimate)) + " bytes, Measurement " +
                                std::to_string(sizeof(Measurement)) + " bytes, " +
                                (*reinterpret_cast<const std::uint8_t*>(&one) ? "little" : "big") +
                                " endian");  // results travel as raw bytes
  id.add("--seed", std::to_string(opt.seed));
  id.add("--runs", std::to_string(opt.runs));
  id.add("the number of nodes", std::to_string(g.nodes.size()));
  for (const auto& n : g.nodes) {
    id.add("node " + n.config.id, n.config.type);
    for (const auto& [name, value] : n.params.values()) {
      const Value* written = n.config.params.find(name);
      id.add(n.config.id + "." + name, canonical(value),
             written && written->is_scalar() ? written->scalar : value.from_default ? canonical(value) + " (its default)" : "");
    }
  }
  for (const std::string& path : trackflow::detail::noted_data_files()) id.add("data file '" + path + "'", file_identity(path));
  return id;
}

std::vector<std::uint64_t> item_hashes(const Identity& id) {
  std::vector<std::uint64_t> h(id.names.size());
  for (size_t i = 0; i < h.size(); ++i) {
    Fnv f;
    f.mix(id.names[i]);
    f.mix(id.texts[i]);
    h[i] = f.h;
  }
  return h;
}

// The ranks compare one hash of everything; when they differ, rank 0 collects each rank's item
// hashes, finds the first rank and item that differ from its own, and that rank sends the item's
// name and value for the message (a few bytes, not every parameter of every rank). Collective:
// every rank calls it; rank 0 throws the refusal, the others ReportedElsewhere.
void agree_on_identity(const Graph& g, const RunOptions& opt, mpi::communicator& world) {
  const Identity id = identity_of(g, opt);
  const std::vector<std::uint64_t> items = item_hashes(id);
  Fnv all;
  all.mix(items.data(), items.size() * sizeof items[0]);
  const long long mine = static_cast<long long>(all.h >> 1);
  const long long lo = mpi::all_reduce(world, mine, mpi::minimum<long long>());
  const long long hi = mpi::all_reduce(world, mine, mpi::maximum<long long>());
  if (lo == hi) return;
  const MPI_Comm comm = world;
  auto pack = [](const std::vector<std::uint64_t>& v) {
    return std::string(reinterpret_cast<const char*>(v.data()), v.size() * sizeof v[0]);
  };
  std::uint64_t where[2] = {0, 0};  // rank, item
  if (world.rank() == 0) {
    for (int r = 1; r < world.size(); ++r) {
      const std::string theirs = recv_bytes(comm, r, kIdentity);
      if (where[0] != 0) continue;
      std::vector<std::uint64_t> other(theirs.size() / sizeof(std::uint64_t));
      std::memcpy(other.data(), theirs.data(), other.size() * sizeof other[0]);
      if (other == items) continue;
      std::size_t i = 0;
      while (i < other.size() && i < items.size() && other[i] == items[i]) ++i;
      where[0] = static_cast<std::uint64_t>(r);
      where[1] = i;
    }
  } else {
    send_bytes(comm, 0, kIdentity, pack(items));
  }
  MPI_Bcast(where, 2, MPI_UINT64_T, 0, comm);
  if (where[0] == 0) {  // every rank's item hashes equal rank 0's, yet the totals differed: cannot be
    if (world.rank() != 0) throw ReportedElsewhere();
    throw ConfigError("the processes of this MPI job do not run the same pipeline");
  }
  const int r = static_cast<int>(where[0]);
  const std::size_t i = where[1];
  auto item_text = [&](std::size_t k) {
    return k < id.names.size() ? id.names[k] + std::string(1, '\0') + id.shown[k] : std::string();
  };
  if (world.rank() == r) send_bytes(comm, 0, kIdentity, item_text(i));
  if (world.rank() != 0) throw ReportedElsewhere();
  const std::string theirs = recv_bytes(comm, r, kIdentity);
  const std::size_t cut = theirs.find('\0');
  const std::string their_name = cut == std::string::npos ? std::string() : theirs.substr(0, cut);
  const std::string their_value = cut == std::string::npos ? std::string() : theirs.substr(cut + 1);
  const std::string rank = "rank " + std::to_string(r);
  std::string what;
  if (i < id.names.size() && their_name == id.names[i])
    what = rank + " differs from rank 0 in " + quote_token(id.names[i], 200) + ": '" + quote_token(their_value, 200) +
           "' vs '" + quote_token(id.shown[i], 200) + "'";
  else if (i >= id.names.size())
    what = rank + " has " + quote_token(their_name, 200) + " ('" + quote_token(their_value, 200) +
           "'), which rank 0 has not";
  else if (their_name.empty())
    what = "rank 0 has " + quote_token(id.names[i], 200) + " ('" + quote_token(id.shown[i], 200) + "'), which " + rank +
           " has not";
  else
    what = rank + " has " + quote_token(their_name, 200) + " ('" + quote_token(their_value, 200) + "') where rank 0 has " +
           quote_token(id.names[i], 200) + " ('" + quote_token(id.shown[i], 200) + "')";
  throw ConfigError("the processes of this MPI job do not run the same pipeline: " + what +
                    " (every process must run the same pipeline, --set, data files, --runs, --seed, plugins and "
                    "trackflow build)");
}

// How many runs rank 0 hands out ahead of the oldest one not merged: four per thread of the job
// (every process runs `threads`), as the threaded engine's window. TRACKFLOW_MPI_WINDOW=N sets it
// (tests run with 1, where most requests wait for a merge); a value that is not a whole number
// from 1 to 10^12 - 1 is reported in the summary's warnings and the default used (rank 0 cannot
// stop here: the other processes already wait for runs).
std::uint64_t mpi_window(unsigned threads, int processes, std::vector<std::string>& warnings) {
  const std::uint64_t fallback = 4 * static_cast<std::uint64_t>(threads) * static_cast<std::uint64_t>(std::max(1, processes));
  if (const char* v = std::getenv("TRACKFLOW_MPI_WINDOW")) {
    const std::string text = v;
    // Digits only (strtoull would take "-1" as 2^64 - 1), and small enough to add to a run index.
    if (!text.empty() && text.size() <= 12 && text.find_first_not_of("0123456789") == std::string::npos) {
      const std::uint64_t n = std::stoull(text);
      if (n >= 1) return n;
    }
    warnings.push_back(std::string("engine: TRACKFLOW_MPI_WINDOW='") + v + "' is not a whole number from 1 to 999999999999; using " +
                       std::to_string(fallback));
  }
  return fallback;
}

// A failure of a run, as rank 0 will report it.
// What the CLI makes of it, as the threaded engine's errors: a ConfigError exits 2 with its message
// as it is, a DataError exits 2, an InternalError (a plugin's bug: rethrow_from_plugin) exits 3.
enum class FailureKind : char { Config = 'C', Data = 'D', Internal = 'I' };
struct Failure {
  FailureKind kind = FailureKind::Data;
  std::string message;
};
std::string encode(const Failure& f) { return static_cast<char>(f.kind) + f.message; }
Failure decode(const std::string& s) {
  if (s.empty()) return {};
  const char k = s[0];
  return {k == 'C' ? FailureKind::Config : k == 'I' ? FailureKind::Internal : FailureKind::Data, s.substr(1)};
}
std::exception_ptr as_error(const Failure& f) {
  if (f.kind == FailureKind::Config) return std::make_exception_ptr(ConfigError(f.message));
  if (f.kind == FailureKind::Internal) return std::make_exception_ptr(InternalError(f.message));
  return std::make_exception_ptr(DataError(f.message));
}

// The failure of run `run` on `rank`. Errors from plugin code come through rethrow_from_plugin,
// which names the node and the run already ("run R: node ..." for bad data, "node ... during
// run R threw" for a bug): the run is added only where the message lacks it. A merge that fails
// is described with the run merged, not the run just finished.
Failure describe(int rank, std::uint64_t run, const std::exception_ptr& error) {
  try {
    std::rethrow_exception(error);
  } catch (const ConfigError& c) {
    return {FailureKind::Config, c.message()};
  } catch (const std::exception& e) {
    const std::string prefix = "run " + std::to_string(run) + ": ";
    std::string what = e.what();
    const bool names_run = what.rfind(prefix, 0) == 0 || what.find(" during run " + std::to_string(run) + " ") != std::string::npos;
    if (!names_run) what = prefix + what;
    if (dynamic_cast<const std::bad_alloc*>(&e))  // as one process reports it: exit 3
      return {FailureKind::Internal, "rank " + std::to_string(rank) + ": " + prefix + "out of memory"};
    const FailureKind kind = dynamic_cast<const InternalError*>(&e) ? FailureKind::Internal : FailureKind::Data;
    return {kind, "rank " + std::to_string(rank) + ": " + what};
  } catch (...) {
    return {FailureKind::Data, "rank " + std::to_string(rank) + ": run " + std::to_string(run) + ": unknown error"};
  }
}

// Ranks > 0: the runs rank 0 assigned to this process, for its worker threads, and their
// results as messages for rank 0 (MPI is called from the main thread only: MPI_THREAD_FUNNELED).
class AssignedRuns final : public RunSource {
 public:
  AssignedRuns(const Graph& g, int rank) : g_(g), rank_(rank) {}

  std::optional<std::uint64_t> next_run() override {
    std::unique_lock<std::mutex> lock(m_);
    cv_work_.wait(lock, [&] { return shutdown_ || !queue_.empty(); });
    if (queue_.empty()) return std::nullopt;
    const std::uint64_t run = queue_.front();
    queue_.pop_front();
    return run;
  }
  void finished(std::uint64_t run, RunRecord&& rec, const GraphInstance& ran_on) override {
    std::pair<int, std::string> msg{kResult, {}};
    try {
      check_codecs(g_, ran_on, rec);
      save_record(rec, run, ran_on, msg.second);
    } catch (...) {
      return failed(run, std::current_exception());
    }
    post(std::move(msg));
  }
  void failed(std::optional<std::uint64_t> run, std::exception_ptr error) override {
    if (!run) return;  // a thread without its instance fails each run it is given (named there)
    std::pair<int, std::string> msg{kError, {}};
    ByteWriter w(msg.second);
    w.put(*run);
    w.put_string(encode(describe(rank_, *run, error)));
    post(std::move(msg));
  }

  void assign(const std::vector<std::uint64_t>& runs) {
    {
      std::lock_guard<std::mutex> lock(m_);
      queue_.insert(queue_.end(), runs.begin(), runs.end());
    }
    cv_work_.notify_all();
  }
  void stop() {
    {
      std::lock_guard<std::mutex> lock(m_);
      shutdown_ = true;
    }
    cv_work_.notify_all();
  }
  // The messages of finished runs: waits up to `timeout` for one (forever: none).
  std::deque<std::pair<int, std::string>> outgoing(std::optional<std::chrono::microseconds> timeout) {
    std::deque<std::pair<int, std::string>> ready;
    std::unique_lock<std::mutex> lock(m_);
    if (!timeout)
      cv_out_.wait(lock, [&] { return !outbox_.empty(); });
    else if (timeout->count() > 0)
      cv_out_.wait_for(lock, *timeout, [&] { return !outbox_.empty(); });
    ready.swap(outbox_);
    return ready;
  }

 private:
  void post(std::pair<int, std::string>&& msg) {
    {
      std::lock_guard<std::mutex> lock(m_);
      outbox_.push_back(std::move(msg));
    }
    cv_out_.notify_one();
  }
  const Graph& g_;
  const int rank_;
  std::mutex m_;
  std::condition_variable cv_work_, cv_out_;
  std::deque<std::uint64_t> queue_;
  std::deque<std::pair<int, std::string>> outbox_;  // (tag, payload)
  bool shutdown_ = false;
};

// Ranks > 0: ask for runs, run them on opt.threads threads, send the results back.
Outcome worker_rank(const Graph& g, const PluginRegistry& registry, const RunOptions& opt, mpi::communicator& world,
                    unsigned threads) {
  const MPI_Comm comm = world;
  const int rank = world.rank();
  AssignedRuns source(g, rank);
  WorkerPool pool(g, registry, opt, source);
  // A process limit may leave fewer threads: the runs assigned here wait for them. None: this
  // process cannot run the runs rank 0 would hand it, and rank 0 would wait for them forever.
  if (const std::string short_of_threads = pool.start(threads); !short_of_threads.empty() && !pool.running()) {
    std::fprintf(stderr, "trackflow: rank %d: %s; aborting the job\n", rank, short_of_threads.c_str());
    MPI_Abort(comm, 3);
  }
  std::uint64_t in_flight = 0;
  bool stop = false, asked = false;
  std::vector<std::uint64_t> assigned(threads);  // rank 0 answers a request with at most as many runs
  MPI_Request answer = MPI_REQUEST_NULL;
  try {
    for (;;) {
      // Rank 0 may hold a request back (its window), so the answer is polled for, not waited on:
      // meanwhile this process's finished runs still go out, and one of them may be the run rank 0
      // waits for. Runs that come after a failure here are still run (they report).
      // The receive is posted with the request, so rank 0's answer never waits for this process
      // (which may be inside a long send of results to it).
      if (!stop && !asked && in_flight < threads) {
        send_u64(comm, 0, kRequest, threads - in_flight);
        MPI_Irecv(assigned.data(), static_cast<int>(assigned.size()), MPI_UINT64_T, 0, kAssign, comm, &answer);
        asked = true;
      }
      bool answered = false;
      if (asked) {
        int flag = 0, count = 0;
        MPI_Status st;
        MPI_Test(&answer, &flag, &st);
        if (flag) {
          MPI_Get_count(&st, MPI_UINT64_T, &count);
          const std::vector<std::uint64_t> runs(assigned.begin(), assigned.begin() + count);
          asked = false;
          answered = true;
          if (runs.empty()) stop = true;
          source.assign(runs);
          in_flight += runs.size();
        }
      }
      if (in_flight == 0 && stop && !asked) break;
      // Answered: free threads may ask again at once. Asked: an answer may come, look again soon.
      // Otherwise every thread is busy (or stopping): only a finished run can come.
      using std::chrono::microseconds;
      const auto ready = source.outgoing(answered ? std::optional<microseconds>(microseconds(0))
                                                  : asked ? std::optional<microseconds>(microseconds(200)) : std::nullopt);
      for (const auto& [tag, payload] : ready) {
        send_bytes(comm, 0, tag, payload);
        --in_flight;
        if (tag == kError) stop = true;  // no new runs; what is in flight still reports
      }
    }
  } catch (...) {
    // An MPI failure mid-exchange: rank 0 would wait for this process forever.
    std::fprintf(stderr, "trackflow: rank %d: the MPI exchange with rank 0 failed; aborting the job\n", rank);
    MPI_Abort(comm, 3);
    throw;
  }
  source.stop();
  pool.join();
  send_u64(comm, 0, kDone, 0);
  if (recv_u64(comm, 0, kFinal) != 0) throw ReportedElsewhere();
  return empty_outcome(g, opt.runs);
}

// Rank 0's own threads: runs from the dispatcher, results checked as on every other process.
class RankZeroRuns final : public RunSource {
 public:
  RankZeroRuns(const Graph& g, RunDispatcher& d) : g_(g), d_(d) {}
  std::optional<std::uint64_t> next_run() override { return d_.next_run(); }
  void finished(std::uint64_t run, RunRecord&& rec, const GraphInstance& ran_on) override {
    try {
      check_codecs(g_, ran_on, rec);
    } catch (...) {
      return d_.failed(run, std::current_exception());
    }
    d_.finished(run, std::move(rec), ran_on);
  }
  void failed(std::optional<std::uint64_t> run, std::exception_ptr error) override { d_.failed(run, error); }

 private:
  const Graph& g_;
  RunDispatcher& d_;
};

// Rank 0: hands the dispatcher's runs to its own threads and to the other processes as they ask
// (a request the window holds back is answered when it moves), and gives their results back.
class MpiRanks final : public Transport {
 public:
  MpiRanks(const Graph& g, const PluginRegistry& registry, const RunOptions& opt, mpi::communicator& world,
           unsigned threads, const GraphInstance& aggregate)
      : g_(g), registry_(registry), opt_(opt), world_(world), threads_(threads), aggregate_(aggregate) {}

  std::uint64_t window(std::vector<std::string>& warnings) override { return mpi_window(threads_, world_.size(), warnings); }

  std::exception_ptr attribute(std::optional<std::uint64_t> run, std::exception_ptr error) const override {
    if (run) return as_error(describe(0, *run, error));
    try {
      std::rethrow_exception(error);
    } catch (const std::exception& e) {
      return std::make_exception_ptr(DataError(std::string("rank 0: ") + e.what()));
    } catch (...) {
      return std::make_exception_ptr(DataError("rank 0: unknown error"));
    }
  }

  void carry(RunDispatcher& d) override {
    const MPI_Comm comm = world_;
    RankZeroRuns own(g_, d);
    WorkerPool pool(g_, registry_, opt_, own);
    // Under a process limit rank 0 may run fewer threads or none: the other processes run the rest.
    if (const std::string short_of_threads = pool.start(threads_); !short_of_threads.empty()) d.warn(short_of_threads);
    int running_ranks = world_.size() - 1;
    std::deque<std::pair<int, std::uint64_t>> held_back;  // requests (rank, runs) the window holds back
    try {
      while (running_ranks > 0 || pool.running()) {
        while (!held_back.empty()) {
          const auto given = d.take(held_back.front().second);
          if (given.empty() && !d.exhausted()) break;
          send_runs(comm, held_back.front().first, given);
          held_back.pop_front();
        }
        int flag = 0;
        MPI_Status st;
        MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, comm, &flag, &st);
        if (flag) {
          receive(d, st.MPI_SOURCE, st.MPI_TAG, held_back, running_ranks);
          continue;
        }
        d.show_progress();
        std::this_thread::sleep_for(std::chrono::microseconds(50));
      }
    } catch (const std::exception& e) {
      // An MPI failure mid-exchange: the other processes would wait for rank 0 forever.
      std::fprintf(stderr, "trackflow: rank 0: the MPI exchange failed (%s); aborting the job\n", e.what());
      MPI_Abort(comm, 3);
      throw;
    }
    pool.join();
    const std::uint64_t status = d.has_failed() ? 1 : 0;
    for (int r = 1; r < world_.size(); ++r) send_u64(comm, r, kFinal, status);
  }

 private:
  void receive(RunDispatcher& d, int src, int tag, std::deque<std::pair<int, std::uint64_t>>& held_back, int& running_ranks) {
    const MPI_Comm comm = world_;
    switch (tag) {
      case kRequest: {
        const std::uint64_t n = recv_u64(comm, src, kRequest);
        const auto given = d.take(n);
        if (!given.empty() || d.exhausted())
          send_runs(comm, src, given);  // none: stop
        else
          held_back.emplace_back(src, n);
        return;
      }
      case kResult: {
        const std::string bytes = recv_bytes(comm, src, kResult);
        ByteReader in(bytes.data(), bytes.size());
        std::uint64_t run = 0;
        RunRecord rec;
        try {
          run = in.get<std::uint64_t>();
          rec = load_record(in, aggregate_);  // the codecs are const: no lock needed
        } catch (const std::exception& e) {
          d.failed_elsewhere(run, std::make_exception_ptr(DataError("rank " + std::to_string(src) + ": run " +
                                                                    std::to_string(run) + ": " + e.what())));
          return;
        }
        d.complete(run, std::move(rec));
        return;
      }
      case kError: {
        const std::string bytes = recv_bytes(comm, src, kError);
        ByteReader in(bytes.data(), bytes.size());
        const auto run = in.get<std::uint64_t>();
        d.failed_elsewhere(run, as_error(decode(in.get_string())));
        return;
      }
      case kDone:
        recv_u64(comm, src, kDone);
        --running_ranks;
        return;
      default:
        throw std::runtime_error("unexpected MPI message tag " + std::to_string(tag) + " from rank " + std::to_string(src));
    }
  }

  const Graph& g_;
  const PluginRegistry& registry_;
  const RunOptions& opt_;
  mpi::communicator& world_;
  const unsigned threads_;
  const GraphInstance& aggregate_;
};

// Rank 0: the dispatcher over the MPI ranks; it merges everything in run order.
Outcome root_rank(const Graph& g, const PluginRegistry& registry, const RunOptions& opt, mpi::communicator& world,
                  unsigned threads) {
  GraphInstance aggregate = instantiate(g, registry);
  MpiRanks transport(g, registry, opt, world, threads, aggregate);
  return dispatch_ensemble(g, aggregate, opt, opt.runs, transport);
}

}  // namespace

bool mpi_built() { return true; }

std::unique_ptr<MpiSession> start_mpi_if_launched(int& argc, char**& argv) {
  const int tasks = detail::slurm_tasks();
  if (!detail::mpi_launched()) {
    if (tasks > 1) detail::refuse_unconnected(tasks, "not as an MPI job (with Slurm: srun --mpi=pmix)");
    return nullptr;
  }
  auto s = std::make_unique<Session>(argc, argv);
  if (s->size() >= 2) return s;
  if (tasks > 1) detail::refuse_unconnected(tasks, "MPI sees a job of one process (with Slurm: srun --mpi=pmix)");
  return nullptr;  // a job of one: MPI stays initialised until exit, nothing is shared
}

Outcome run_graph_distributed(const Graph& g, const PluginRegistry& registry, const RunOptions& opt, MpiSession& session) {
  auto& s = dynamic_cast<Session&>(session);
  mpi::communicator& world = s.world();
  RunOptions o = opt;
  o.runs = std::max<std::uint64_t>(1, opt.runs);
  const unsigned threads = std::max(1u, opt.threads);
  agree_on_identity(g, o, world);
  if (world.rank() == 0) return root_rank(g, registry, o, world, threads);
  return worker_rank(g, registry, o, world, threads);
}

}  // namespace trackflow::host
