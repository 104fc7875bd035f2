// Purpose: the Monte Carlo ensemble across the processes of an MPI job (Open MPI through Boost.MPI): rank 0 hands out runs in order, every process runs them on its threads, results come back as bytes and are merged in run order on rank 0.
#include <trackflow/host/guard.hpp>
#include <trackflow/host/mpi.hpp>
#include <trackflow/rng.hpp>
#include <trackflow/run_result_codec.hpp>
#include <trackflow/version.hpp>

#include "mpi_launch.hpp"
#include "run_one.hpp"

#include <boost/mpi/collectives.hpp>
#include <boost/mpi/communicator.hpp>
#include <boost/mpi/environment.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <limits>
#include <map>
#include <mutex>
#include <new>
#include <thread>

namespace trackflow::host {
namespace {

namespace mpi = boost::mpi;

// Point-to-point messages of one distributed run. Workers (ranks > 0) send kRequest (how many
// runs they can take) and get kAssign (run indices; none: stop); they send each run's kResult
// (the index, then the record's bytes) or kError, then kDone; rank 0 ends with kFinal (0 ok,
// 1 failed) to each once all are done, so every process leaves at the same point.
enum Tag : int { kRequest = 101, kAssign, kResult, kError, kDone, kFinal, kPayload };

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

// One instance of the graph on one thread, running whole runs (the steps of engine.cpp's worker).
struct Runner {
  const Graph& g;
  const RunOptions& opt;
  GraphInstance inst;
  std::vector<Filter*> filters;
  NodeLabels labels;
  Runner(const Graph& graph, const PluginRegistry& registry, const RunOptions& o)
      : g(graph), opt(o), inst(instantiate(graph, registry)), filters(filters_of(inst)), labels(labels_of(g, inst)) {}
  RunRecord run(std::uint64_t run) {
    const size_t N = g.nodes.size();
    RunRecord rec;
    {
      Activity running{"running", &labels};
      running.run = run;
      running.has_run = true;
      ActivityScope scope(running);
      try {
        rec = run_one(g, inst, filters, opt.seed, run);
      } catch (...) {
        rethrow_from_plugin();  // names the run, the node and its plugin file
      }
    }
    // Checked on every process, whichever runs the run, so the job behaves the same for any -np.
    for (size_t i = 0; i < N; ++i)
      if (rec.results[i] && !dynamic_cast<const RunResultCodec*>(inst.components[i].get()))
        throw ConfigError("node '" + g.nodes[i].config.id + "' (" + g.nodes[i].config.type +
                          ") returns per-run results that cannot be sent between the processes of an MPI job: its "
                          "plugin does not implement trackflow::RunResultCodec (run_result_codec.hpp). Run this "
                          "pipeline without mpirun (--threads N uses one machine's cores).");
    return rec;
  }
  void save(const RunRecord& rec, std::uint64_t run, std::string& out) const {
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
      if (rec.results[i])
        dynamic_cast<const RunResultCodec&>(*inst.components[i]).save_run_result(*rec.results[i], w);
    }
  }
};

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

// What the processes of one job must share for their runs to be interchangeable.
long long fingerprint(const Graph& g, const RunOptions& opt) {
  std::uint64_t h = 1469598103934665603ull;
  auto mix = [&h](std::uint64_t v) { h = (h ^ v) * 1099511628211ull; };
  mix(static_cast<std::uint64_t>(kAbiVersion));
  mix(sizeof(Estimate));
  mix(sizeof(Measurement));
  const std::uint16_t one = 1;
  mix(*reinterpret_cast<const std::uint8_t*>(&one));  // byte order: results travel as raw bytes
  mix(opt.seed);
  mix(opt.runs);
  for (const auto& n : g.nodes)
    for (char c : n.config.id + "/" + n.config.type) mix(static_cast<unsigned char>(c));
  return static_cast<long long>(h >> 1);
}

// How many runs rank 0 hands out ahead of the oldest one not merged: four per thread of the job
// (every process runs `threads`), as engine.cpp's window. TRACKFLOW_MPI_WINDOW=N sets it (tests
// run with 1, where most requests wait for a merge); a value that is not a whole number from 1
// to 10^12 - 1 is reported in the summary's warnings and the default used (rank 0 cannot stop here:
// the other processes already wait for runs).
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
[[noreturn]] void throw_failure(const Failure& f) {
  if (f.kind == FailureKind::Config) throw ConfigError(f.message);
  if (f.kind == FailureKind::Internal) throw InternalError(f.message);
  throw DataError(f.message);
}

// The failure of run `run` on `rank`. Errors from plugin code come through rethrow_from_plugin,
// which names the node and the run already ("run R: node ..." for bad data, "node ... during
// run R threw" for a bug): the run is added only where the message lacks it.
Failure describe(int rank, std::uint64_t run, const std::exception& e) {
  if (const auto* c = dynamic_cast<const ConfigError*>(&e)) return {FailureKind::Config, c->message()};
  const std::string prefix = "run " + std::to_string(run) + ": ";
  std::string what = e.what();
  const bool names_run = what.rfind(prefix, 0) == 0 || what.find(" during run " + std::to_string(run) + " ") != std::string::npos;
  if (!names_run) what = prefix + what;
  if (dynamic_cast<const std::bad_alloc*>(&e))  // as one process reports it: exit 3
    return {FailureKind::Internal, "rank " + std::to_string(rank) + ": " + prefix + "out of memory"};
  const FailureKind kind = dynamic_cast<const InternalError*>(&e) ? FailureKind::Internal : FailureKind::Data;
  return {kind, "rank " + std::to_string(rank) + ": " + what};
}

// Ranks > 0: ask for runs, run them on opt.threads threads, send the results back.
Outcome worker_rank(const Graph& g, const PluginRegistry& registry, const RunOptions& opt, mpi::communicator& world,
                    unsigned threads) {
  const MPI_Comm comm = world;
  const int rank = world.rank();  // MPI is called from this thread only (MPI_THREAD_FUNNELED)
  std::mutex m;
  std::condition_variable cv_work, cv_out;
  std::deque<std::uint64_t> queue;
  std::deque<std::pair<int, std::string>> outbox;  // (tag, payload)
  bool shutdown = false;
  auto worker = [&]() {
    prepare_thread_for_crash_reports();  // a stack overflow in a plugin is named here too
    // As in engine.cpp: a sink that keeps a large run's rows in a temporary file asks
    // output_directory() (none there, or none possible: they stay in memory).
    OutputDirectoryScope dir(opt.output_dir);
    std::unique_ptr<Runner> runner;
    std::string setup_error;
    try {
      runner = std::make_unique<Runner>(g, registry, opt);
    } catch (const std::exception& e) {
      setup_error = e.what();
    }
    for (;;) {
      std::uint64_t run;
      {
        std::unique_lock<std::mutex> lock(m);
        cv_work.wait(lock, [&] { return shutdown || !queue.empty(); });
        if (queue.empty()) return;
        run = queue.front();
        queue.pop_front();
      }
      std::pair<int, std::string> msg;
      try {
        if (!runner) throw DataError("could not build the pipeline on this process: " + setup_error);
        RunRecord rec = runner->run(run);
        msg.first = kResult;
        runner->save(rec, run, msg.second);
      } catch (const std::exception& e) {
        msg = {kError, encode(describe(rank, run, e))};
      }
      {
        std::lock_guard<std::mutex> lock(m);
        outbox.push_back(std::move(msg));
      }
      cv_out.notify_one();
    }
  };
  std::vector<std::thread> pool;
  for (unsigned t = 0; t < threads; ++t) pool.emplace_back(worker);
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
          if (runs.empty()) {
            stop = true;
          } else {
            {
              std::lock_guard<std::mutex> lock(m);
              queue.insert(queue.end(), runs.begin(), runs.end());
            }
            in_flight += runs.size();
            cv_work.notify_all();
          }
        }
      }
      if (in_flight == 0 && stop && !asked) break;
      std::deque<std::pair<int, std::string>> ready;
      {
        std::unique_lock<std::mutex> lock(m);
        if (answered) {
          // free threads may ask again at once
        } else if (asked) {  // an answer may come: look again soon
          cv_out.wait_for(lock, std::chrono::microseconds(200), [&] { return !outbox.empty(); });
        } else {  // every thread busy (or stopping): only a finished run can come
          cv_out.wait(lock, [&] { return !outbox.empty(); });
        }
        ready.swap(outbox);
      }
      for (auto& [tag, payload] : ready) {
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
  {
    std::lock_guard<std::mutex> lock(m);
    shutdown = true;
  }
  cv_work.notify_all();
  for (auto& t : pool) t.join();
  send_u64(comm, 0, kDone, 0);
  if (recv_u64(comm, 0, kFinal) != 0) throw ReportedElsewhere();
  return empty_outcome(g, opt.runs);
}

// Rank 0: hands out runs, runs some itself, merges everything in run order.
Outcome root_rank(const Graph& g, const PluginRegistry& registry, const RunOptions& opt, mpi::communicator& world,
                  unsigned threads) {
  const MPI_Comm comm = world;
  const std::uint64_t runs = opt.runs;
  Outcome out = empty_outcome(g, runs);
  GraphInstance aggregate = instantiate(g, registry);
  // Results received from the other processes are loaded and merged on this thread, and finish()
  // runs here: streaming sinks (sink.csv) write into --out as they merge, as in engine.cpp.
  OutputDirectoryScope dir(opt.output_dir);

  // Handing out runs: in order, to whoever asks (its own threads and the other processes), at most
  // `window` runs ahead of the oldest one not yet merged, as engine.cpp's workers: finished runs
  // wait on this process until every earlier run is merged, so a slow run must not let them pile
  // up without bound. A request the window holds back is answered when the window moves.
  std::mutex dispense_mutex;
  std::uint64_t next_run = 0;
  std::atomic<std::uint64_t> merged_runs{0};
  const std::uint64_t window = mpi_window(threads, world.size(), out.warnings);
  std::atomic<bool> failed{false};
  Failure failure;
  bool has_failure = false;
  std::condition_variable window_moved;  // rank 0's own threads wait on it (with merge_mutex)
  auto fail = [&](Failure f) {
    {
      std::lock_guard<std::mutex> lock(dispense_mutex);
      if (!has_failure) {
        failure = std::move(f);
        has_failure = true;
      }
      failed = true;
    }
    window_moved.notify_all();
  };
  auto take = [&](std::uint64_t n) {
    std::vector<std::uint64_t> out_runs;
    std::lock_guard<std::mutex> lock(dispense_mutex);
    const std::uint64_t merged = merged_runs.load();
    const std::uint64_t limit = window >= runs - std::min(merged, runs) ? runs : merged + window;
    while (!failed && next_run < runs && next_run < limit && out_runs.size() < n) out_runs.push_back(next_run++);
    return out_runs;
  };
  // No run will be handed out any more (all are, or the job failed).
  auto exhausted = [&] {
    std::lock_guard<std::mutex> lock(dispense_mutex);
    return failed || next_run >= runs;
  };

  // Merging in run order, as engine.cpp does, whichever thread or process ran the run.
  const NodeLabels aggregate_labels = labels_of(g, aggregate);
  RunOrderMerge merger(aggregate, aggregate_labels, runs, out);
  std::mutex merge_mutex;
  // A merge that fails names its node and run (rethrow_from_plugin), not the run just finished.
  auto complete = [&](std::uint64_t run, RunRecord&& rec) {
    try {
      std::lock_guard<std::mutex> lock(merge_mutex);
      merger.complete(run, std::move(rec));
      merged_runs = merger.merged();
      window_moved.notify_all();
    } catch (const ConfigError& e) {
      fail({FailureKind::Config, e.message()});
    } catch (const std::bad_alloc&) {
      fail({FailureKind::Internal, "rank 0: run " + std::to_string(run) + ": out of memory"});
    } catch (const std::exception& e) {
      fail({dynamic_cast<const InternalError*>(&e) ? FailureKind::Internal : FailureKind::Data,
            std::string("rank 0: ") + e.what()});
    }
  };

  std::atomic<unsigned> active{threads};
  auto worker = [&]() {
    prepare_thread_for_crash_reports();
    OutputDirectoryScope dir(opt.output_dir);  // merges happen here too: sink.csv streams its file
    try {
      Runner runner(g, registry, opt);
      for (;;) {
        const auto mine = take(1);
        if (mine.empty()) {
          if (exhausted()) break;
          std::unique_lock<std::mutex> lock(merge_mutex);  // the window is full: wait for a merge
          window_moved.wait_for(lock, std::chrono::milliseconds(10));
          continue;
        }
        RunRecord rec;
        try {
          rec = runner.run(mine[0]);
        } catch (const std::exception& e) {
          fail(describe(0, mine[0], e));
          continue;
        }
        complete(mine[0], std::move(rec));
      }
    } catch (const std::exception& e) {
      fail({FailureKind::Data, std::string("rank 0: ") + e.what()});
    }
    --active;
  };

  const auto t0 = std::chrono::steady_clock::now();
  std::vector<std::thread> pool;
  for (unsigned t = 0; t < threads; ++t) pool.emplace_back(worker);
  int running_ranks = world.size() - 1;
  std::deque<std::pair<int, std::uint64_t>> held_back;  // requests (rank, runs) the window holds back
  auto last_progress = std::chrono::steady_clock::now();
  try {
    while (running_ranks > 0 || active.load() > 0) {
      while (!held_back.empty()) {
        const auto given = take(held_back.front().second);
        if (given.empty() && !exhausted()) break;
        send_runs(comm, held_back.front().first, given);
        held_back.pop_front();
      }
      int flag = 0;
      MPI_Status st;
      MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, comm, &flag, &st);
      if (flag) {
        const int src = st.MPI_SOURCE;
        switch (st.MPI_TAG) {
          case kRequest: {
            const std::uint64_t n = recv_u64(comm, src, kRequest);
            const auto given = take(n);
            if (!given.empty() || exhausted())
              send_runs(comm, src, given);  // none: stop
            else
              held_back.emplace_back(src, n);
            break;
          }
          case kResult: {
            const std::string bytes = recv_bytes(comm, src, kResult);
            ByteReader in(bytes.data(), bytes.size());
            std::uint64_t run = 0;
            RunRecord rec;
            try {
              run = in.get<std::uint64_t>();
              rec = load_record(in, aggregate);  // the codecs are const: no lock needed
            } catch (const std::exception& e) {
              fail({FailureKind::Data, "rank " + std::to_string(src) + ": run " + std::to_string(run) + ": " + e.what()});
              break;
            }
            complete(run, std::move(rec));
            break;
          }
          case kError:
            fail(decode(recv_bytes(comm, src, kError)));
            break;
          case kDone:
            recv_u64(comm, src, kDone);
            --running_ranks;
            break;
          default:
            throw std::runtime_error("unexpected MPI message tag " + std::to_string(st.MPI_TAG) + " from rank " +
                                     std::to_string(src));
        }
        continue;
      }
      if (opt.progress && std::chrono::steady_clock::now() - last_progress > std::chrono::milliseconds(100)) {
        std::uint64_t merged;
        {
          std::lock_guard<std::mutex> lock(merge_mutex);
          merged = merger.merged();
        }
        opt.progress(merged, runs);
        last_progress = std::chrono::steady_clock::now();
      }
      std::this_thread::sleep_for(std::chrono::microseconds(50));
    }
  } catch (const std::exception& e) {
    // An MPI failure mid-exchange: the other processes would wait for rank 0 forever.
    std::fprintf(stderr, "trackflow: rank 0: the MPI exchange failed (%s); aborting the job\n", e.what());
    MPI_Abort(comm, 3);
    throw;
  }
  for (auto& t : pool) t.join();
  const int status = failed ? 1 : 0;
  for (int r = 1; r < world.size(); ++r) send_u64(comm, r, kFinal, static_cast<std::uint64_t>(status));
  if (failed) throw_failure(failure);
  if (merger.merged() != runs) throw std::runtime_error("distributed run ended with " + std::to_string(merger.merged()) + " of " +
                                                   std::to_string(runs) + " runs merged");
  if (opt.progress) opt.progress(runs, runs);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  finish_all(g, aggregate, aggregate_labels, opt, runs, out);
  return out;
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
  const long long mine = fingerprint(g, o);
  const long long lo = mpi::all_reduce(world, mine, mpi::minimum<long long>());
  const long long hi = mpi::all_reduce(world, mine, mpi::maximum<long long>());
  if (lo != hi) {
    if (world.rank() != 0) throw ReportedElsewhere();
    throw ConfigError("the processes of this MPI job do not run the same pipeline (pipeline, --runs, --seed, plugins "
                      "or trackflow build differ between them)");
  }
  if (world.rank() == 0) return root_rank(g, registry, o, world, threads);
  return worker_rank(g, registry, o, world, threads);
}

}  // namespace trackflow::host
