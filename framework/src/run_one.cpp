// Purpose: one Monte Carlo run on one graph instance, shared by the engine and the MPI engine.
#include "run_one.hpp"

#include <trackflow/host/filter_control.hpp>
#include <trackflow/rng.hpp>

#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <string>
#include <utility>

namespace trackflow::host {
namespace {

// Tells the groups_by_time nodes when an instant is over: before the first emission of a later
// time, and after the run's last item. Without such nodes it does nothing.
class InstantCloser {
 public:
  explicit InstantCloser(GraphInstance& inst) : inst_(inst) {}
  void before(double t) {
    if (inst_.time_grouping.empty()) return;
    if (open_ && t > time_) close();
    open_ = true;
    time_ = t;
  }
  void finish() {
    if (open_) close();
    open_ = false;
  }

 private:
  void close() {
    for (int i : inst_.time_grouping) {
      Component* c = inst_.components[i].get();
      detail::executing = c;
      c->on_time_complete(time_);
    }
  }
  GraphInstance& inst_;
  bool open_ = false;
  double time_ = 0.0;
};

// One run on one instance: the generator with the earliest next item goes first; ties go to
// the generator declared first, so the order never depends on timing. A generator whose next
// time is not a number is exhausted, as one at +infinity.
std::uint64_t drive(GraphInstance& inst) {
  std::vector<Generator*> gens;
  for (int r : inst.roots) gens.push_back(static_cast<Generator*>(inst.components[r].get()));
  InstantCloser instants(inst);
  std::uint64_t items = 0;
  if (gens.size() == 1) {
    Generator* g = gens[0];
    detail::executing = g;
    for (double t = g->next_time(); std::isfinite(t); t = g->next_time()) {
      instants.before(t);
      detail::executing = g;
      g->emit_next();
      ++items;
    }
    instants.finish();
    return items;
  }
  if (gens.size() <= 8) {
    for (;;) {
      Generator* best = nullptr;
      double t = std::numeric_limits<double>::infinity();
      for (Generator* g : gens) {
        detail::executing = g;
        const double gt = g->next_time();
        if (gt < t) {
          t = gt;
          best = g;
        }
      }
      if (!best) break;
      instants.before(t);
      detail::executing = best;
      best->emit_next();
      ++items;
    }
    instants.finish();
    return items;
  }
  // Many sources: a heap on (time, declaration order) keeps a step logarithmic. Only the
  // generator that emitted changes its next time (generators have no inputs).
  using Entry = std::pair<double, std::size_t>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> heap;
  for (std::size_t i = 0; i < gens.size(); ++i) {
    detail::executing = gens[i];
    const double t = gens[i]->next_time();
    if (t < std::numeric_limits<double>::infinity()) heap.emplace(t, i);
  }
  while (!heap.empty()) {
    const auto [t0, i] = heap.top();
    heap.pop();
    instants.before(t0);
    detail::executing = gens[i];
    gens[i]->emit_next();
    ++items;
    const double t = gens[i]->next_time();
    if (t < std::numeric_limits<double>::infinity()) heap.emplace(t, i);
  }
  instants.finish();
  return items;
}

}  // namespace

NodeLabels labels_of(const Graph& g, const GraphInstance& inst) {
  NodeLabels l;
  for (std::size_t i = 0; i < g.nodes.size(); ++i) {
    l.components.push_back(inst.components[i].get());
    l.labels.push_back("node '" + g.nodes[i].config.id + "' (" + g.nodes[i].config.type + " from " +
                       g.nodes[i].type->file + ")");
  }
  return l;
}

Outcome empty_outcome(const Graph& g, std::uint64_t runs) {
  Outcome out;
  out.runs = runs;
  out.nodes.resize(g.nodes.size());
  for (size_t i = 0; i < g.nodes.size(); ++i) {
    out.nodes[i].id = g.nodes[i].config.id;
    out.nodes[i].type = g.nodes[i].config.type;
  }
  for (const auto& n : g.nodes)
    if (n.type->decl.kind == ComponentKind::Filter) ++out.filters;
  return out;
}

std::vector<Filter*> filters_of(GraphInstance& inst) {
  std::vector<Filter*> filters;
  for (auto& c : inst.components)
    if (auto* f = dynamic_cast<Filter*>(c.get())) filters.push_back(f);
  return filters;
}

RunRecord run_one(const Graph& g, GraphInstance& inst, const std::vector<Filter*>& filters, std::uint64_t seed,
                  std::uint64_t run) {
  const std::size_t N = g.nodes.size();
  RunRecord rec;
  // The engine, not each filter's discipline, puts back what adapters tuned in the previous
  // run on this instance: otherwise results would depend on which thread ran which run.
  for (Filter* f : filters) {
    detail::executing = f;
    FilterControl::reset_adapted_state(*f);
  }
  for (std::size_t i = 0; i < N; ++i) {
    detail::executing = inst.components[i].get();
    inst.components[i]->start_run({run, derive_seed(seed, run, g.nodes[i].config.id), &rec.diagnostics});
  }
  for (Filter* f : filters) FilterControl::take_processed(*f);  // a failed earlier run may have left counts
  rec.source_items = drive(inst);
  for (Filter* f : filters) rec.measurements_processed += FilterControl::take_processed(*f);
  rec.results.resize(N);
  for (std::size_t i = 0; i < N; ++i) {
    detail::executing = inst.components[i].get();
    rec.results[i] = inst.components[i]->end_run();
  }
  detail::executing = nullptr;
  return rec;
}

void merge_run_diagnostics(const RunRecord& rec, std::uint64_t run, std::uint64_t runs, Outcome& out) {
  out.source_items += rec.source_items;
  out.measurements_processed += rec.measurements_processed;
  for (const auto& s : rec.diagnostics.skips) {
    for (auto& n : out.nodes) {
      if (n.id != s.node) continue;
      ++n.skips;
      if (n.skip_examples.size() < 5)
        n.skip_examples.push_back((runs > 1 ? "run " + std::to_string(run) + ": " : "") + s.message);
    }
  }
  for (const auto& w : rec.diagnostics.warnings)
    if (out.warnings.size() < 20) out.warnings.push_back(w.node + ": " + w.message);
}

void merge_run(GraphInstance& aggregate, const NodeLabels& labels, std::uint64_t run, std::uint64_t runs,
               RunRecord&& rec, Outcome& out) {
  Activity merging{"merging the results of a run", &labels};
  merging.run = run;
  merging.has_run = true;
  ActivityScope scope(merging);
  try {
    for (size_t i = 0; i < rec.results.size(); ++i)
      if (rec.results[i]) {
        detail::executing = aggregate.components[i].get();
        aggregate.components[i]->merge(*rec.results[i]);
      }
  } catch (...) {
    rethrow_from_plugin();
  }
  merge_run_diagnostics(rec, run, runs, out);
}

void finish_all(const Graph& g, GraphInstance& aggregate, const NodeLabels& labels, const RunOptions& opt,
                std::uint64_t runs, Outcome& out) {
  Activity finishing{"finishing", &labels};
  ActivityScope scope(finishing);
  try {
    for (size_t i = 0; i < g.nodes.size(); ++i) {
      FinishContext ctx{g.nodes[i].config.id, opt.output_dir, runs};
      detail::executing = aggregate.components[i].get();
      aggregate.components[i]->finish(out.nodes[i].summary, ctx);
    }
  } catch (...) {
    rethrow_from_plugin();
  }
}

}  // namespace trackflow::host
