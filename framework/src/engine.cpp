// Purpose: the run loop: time-ordered merge of sources, Monte Carlo runs on worker threads, ordered reduction.
#include <trackflow/host/engine.hpp>
#include <trackflow/rng.hpp>

#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <map>
#include <mutex>
#include <thread>

namespace trackflow::host {
namespace {

struct RunRecord {
  std::vector<std::unique_ptr<RunResult>> results;  // by node
  Diagnostics diagnostics;
  std::uint64_t source_items = 0;
  std::uint64_t measurements_processed = 0;
};

// One run on one instance: the generator with the earliest next item goes first; ties go to
// the generator declared first, so the order never depends on timing.
std::uint64_t drive(GraphInstance& inst) {
  std::vector<Generator*> gens;
  for (int r : inst.roots) gens.push_back(static_cast<Generator*>(inst.components[r].get()));
  std::uint64_t items = 0;
  if (gens.size() == 1) {
    Generator* g = gens[0];
    while (std::isfinite(g->next_time())) {
      g->emit_next();
      ++items;
    }
    return items;
  }
  for (;;) {
    Generator* best = nullptr;
    double t = std::numeric_limits<double>::infinity();
    for (Generator* g : gens) {
      const double gt = g->next_time();
      if (gt < t) {
        t = gt;
        best = g;
      }
    }
    if (!best) return items;
    best->emit_next();
    ++items;
  }
}

}  // namespace

const NodeOutcome* Outcome::find(const std::string& id) const {
  for (const auto& n : nodes)
    if (n.id == id) return &n;
  return nullptr;
}

Outcome run_graph(const Graph& g, const PluginRegistry& registry, const RunOptions& opt) {
  const size_t N = g.nodes.size();
  const std::uint64_t runs = std::max<std::uint64_t>(1, opt.runs);
  const unsigned threads = static_cast<unsigned>(std::clamp<std::uint64_t>(opt.threads, 1, runs));
  std::atomic<std::uint64_t> next_run{0}, done{0};
  std::atomic<bool> failed{false};
  std::exception_ptr error;
  std::mutex error_mutex;

  Outcome out;
  out.runs = runs;
  out.nodes.resize(N);
  for (size_t i = 0; i < N; ++i) {
    out.nodes[i].id = g.nodes[i].config.id;
    out.nodes[i].type = g.nodes[i].config.type;
  }

  for (const auto& n : g.nodes)
    if (n.type->decl.kind == ComponentKind::Filter) ++out.filters;

  // The aggregating instance is built first so construction errors surface before any thread starts.
  GraphInstance aggregate = instantiate(g, registry);

  // Finished runs wait here until every earlier run has been merged: merging happens strictly
  // in run order (so sums are identical for any thread count) and memory stays bounded by the
  // runs in flight, not the ensemble size.
  std::map<std::uint64_t, RunRecord> pending;
  std::uint64_t next_merge = 0;
  std::mutex merge_mutex;
  auto merge_one = [&](std::uint64_t r, RunRecord& rec) {
    out.source_items += rec.source_items;
    out.measurements_processed += rec.measurements_processed;
    for (size_t i = 0; i < N; ++i)
      if (rec.results[i]) aggregate.components[i]->merge(*rec.results[i]);
    for (const auto& s : rec.diagnostics.skips) {
      for (auto& n : out.nodes) {
        if (n.id != s.node) continue;
        ++n.skips;
        if (n.skip_examples.size() < 5)
          n.skip_examples.push_back((runs > 1 ? "run " + std::to_string(r) + ": " : "") + s.message);
      }
    }
    for (const auto& w : rec.diagnostics.warnings)
      if (out.warnings.size() < 20) out.warnings.push_back(w.node + ": " + w.message);
  };
  auto complete = [&](std::uint64_t run, RunRecord&& rec) {
    std::lock_guard<std::mutex> lock(merge_mutex);
    pending.emplace(run, std::move(rec));
    for (auto it = pending.find(next_merge); it != pending.end(); it = pending.find(next_merge)) {
      merge_one(it->first, it->second);
      pending.erase(it);
      ++next_merge;
    }
  };

  auto worker = [&]() {
    try {
      GraphInstance inst = instantiate(g, registry);
      std::vector<Filter*> filters;
      for (auto& c : inst.components)
        if (auto* f = dynamic_cast<Filter*>(c.get())) filters.push_back(f);
      for (;;) {
        const std::uint64_t run = next_run.fetch_add(1);
        if (run >= runs || failed.load()) break;
        RunRecord rec;
        try {
          // The engine, not each filter's discipline, puts back what adapters tuned in the previous
          // run on this instance: otherwise results would depend on which thread ran which run.
          for (Filter* f : filters) f->reset_adapted_state();
          for (size_t i = 0; i < N; ++i)
            inst.components[i]->start_run({run, derive_seed(opt.seed, run, g.nodes[i].config.id), &rec.diagnostics});
          for (Filter* f : filters) f->take_processed();  // a failed earlier run may have left counts
          rec.source_items = drive(inst);
          for (Filter* f : filters) rec.measurements_processed += f->take_processed();
          rec.results.resize(N);
          for (size_t i = 0; i < N; ++i) rec.results[i] = inst.components[i]->end_run();
        } catch (const ConfigError&) {
          throw;
        } catch (const std::exception& e) {
          throw DataError("run " + std::to_string(run) + ": " + e.what());
        }
        complete(run, std::move(rec));
        done.fetch_add(1);
      }
    } catch (...) {
      std::lock_guard<std::mutex> lock(error_mutex);
      if (!error) error = std::current_exception();
      failed = true;
    }
  };

  const auto t0 = std::chrono::steady_clock::now();
  std::vector<std::thread> pool;
  for (unsigned t = 0; t < threads; ++t) pool.emplace_back(worker);
  if (opt.progress) {
    while (done.load() < runs && !failed.load()) {
      opt.progress(done.load(), runs);
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    if (!failed.load()) opt.progress(runs, runs);
  }
  for (auto& t : pool) t.join();
  const auto t1 = std::chrono::steady_clock::now();
  if (error) std::rethrow_exception(error);
  out.seconds = std::chrono::duration<double>(t1 - t0).count();

  for (size_t i = 0; i < N; ++i) {
    FinishContext ctx{g.nodes[i].config.id, opt.output_dir, runs};
    aggregate.components[i]->finish(out.nodes[i].summary, ctx);
  }
  return out;
}

}  // namespace trackflow::host
