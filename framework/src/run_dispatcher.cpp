// Purpose: the run dispatcher shared by the threaded and the MPI engine: window, run-order merge, first failure, progress.
#include "run_dispatcher.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>

namespace trackflow::host {

RunDispatcher::RunDispatcher(std::uint64_t runs, std::uint64_t window, MergeRun merge, Progress progress,
                             Attribute attribute, std::vector<std::string>& warnings)
    : runs_(runs),
      window_(std::max<std::uint64_t>(1, window)),
      merge_(std::move(merge)),
      progress_(std::move(progress)),
      attribute_(std::move(attribute)),
      warnings_(warnings) {}

std::vector<std::uint64_t> RunDispatcher::take(std::uint64_t n) {
  std::vector<std::uint64_t> given;
  std::lock_guard<std::mutex> lock(state_mutex_);
  // min(runs, merged + window) without overflow (the window may be set up to 10^12).
  const std::uint64_t limit = window_ >= runs_ - merged_ ? runs_ : merged_ + window_;
  while (!failure_ && next_run_ < limit && given.size() < n) given.push_back(next_run_++);
  return given;
}

bool RunDispatcher::exhausted() const {
  std::lock_guard<std::mutex> lock(state_mutex_);
  return failure_ || next_run_ >= runs_;
}

std::optional<std::uint64_t> RunDispatcher::next_run() {
  std::unique_lock<std::mutex> lock(state_mutex_);
  for (;;) {
    if (failure_ || next_run_ >= runs_) return std::nullopt;
    if (next_run_ - merged_ < window_) return next_run_++;
    changed_.wait(lock);  // the window is full: wait for a merge
  }
}

void RunDispatcher::finished(std::uint64_t run, RunRecord&& rec, const GraphInstance&) { complete(run, std::move(rec)); }

void RunDispatcher::failed(std::optional<std::uint64_t> run, std::exception_ptr error) {
  record_failure(run, attribute_ ? attribute_(run, error) : error);
}

void RunDispatcher::failed_elsewhere(std::optional<std::uint64_t> run, std::exception_ptr error) {
  record_failure(run, std::move(error));
}

void RunDispatcher::complete(std::uint64_t run, RunRecord&& rec) {
  {
    std::lock_guard<std::mutex> merging(merge_mutex_);
    bool dropped;
    {
      std::lock_guard<std::mutex> lock(state_mutex_);
      ++completed_;
      // A run after the failing one is never merged: the job fails anyway, and a merge after a
      // failed merge would repeat the earlier nodes' merges (a sink's rows written twice).
      dropped = failure_ && (!failure_run_ || run > *failure_run_);
    }
    if (!dropped) {
      pending_.emplace(run, std::move(rec));
      for (auto it = pending_.find(next_merge_); it != pending_.end(); it = pending_.find(next_merge_)) {
        try {
          merge_(it->first, std::move(it->second));
        } catch (...) {
          const std::uint64_t failing = next_merge_;  // the run whose merge threw, not the one just finished
          pending_.clear();
          failed(failing, std::current_exception());
          break;
        }
        pending_.erase(it);
        ++next_merge_;
      }
    }
    std::lock_guard<std::mutex> lock(state_mutex_);
    merged_ = next_merge_;
    ++changes_;
  }
  changed_.notify_all();
}

void RunDispatcher::record_failure(std::optional<std::uint64_t> run, std::exception_ptr error) {
  {
    std::lock_guard<std::mutex> lock(state_mutex_);
    // The lowest run's failure is reported (a set-up failure before any): every earlier run was
    // handed out and is carried to its end, so the choice does not depend on timing.
    const bool earlier = !failure_ || (failure_run_ && (!run || *run < *failure_run_));
    if (earlier) {
      failure_ = std::move(error);
      failure_run_ = run;
    }
    ++changes_;
  }
  changed_.notify_all();
}

void RunDispatcher::warn(const std::string& line) {
  std::lock_guard<std::mutex> merging(merge_mutex_);
  if (warnings_.size() < 20) warnings_.push_back(line);
}

bool RunDispatcher::has_failed() const {
  std::lock_guard<std::mutex> lock(state_mutex_);
  return static_cast<bool>(failure_);
}

std::uint64_t RunDispatcher::merged() const {
  std::lock_guard<std::mutex> lock(state_mutex_);
  return merged_;
}

std::uint64_t RunDispatcher::completed() const {
  std::lock_guard<std::mutex> lock(state_mutex_);
  return completed_;
}

std::size_t RunDispatcher::waiting() {
  std::lock_guard<std::mutex> merging(merge_mutex_);
  return pending_.size();
}

void RunDispatcher::show_progress() {
  if (!progress_ || has_failed()) return;
  const auto now = std::chrono::steady_clock::now();
  if (now - last_progress_ < std::chrono::milliseconds(100)) return;
  last_progress_ = now;
  try {
    progress_(completed(), runs_);
  } catch (...) {
    // The progress display is cosmetic; the runs go on.
  }
}

void RunDispatcher::wait_for_change(std::chrono::milliseconds timeout) {
  std::unique_lock<std::mutex> lock(state_mutex_);
  const std::uint64_t seen = changes_;
  changed_.wait_for(lock, timeout, [&] { return changes_ != seen; });
}

void RunDispatcher::conclude() {
  {
    std::lock_guard<std::mutex> lock(state_mutex_);
    if (failure_) std::rethrow_exception(failure_);
  }
  const std::uint64_t done = merged();
  if (done != runs_)
    throw std::runtime_error("the ensemble ended with " + std::to_string(done) + " of " + std::to_string(runs_) +
                             " runs merged");
  if (!progress_) return;
  try {
    progress_(runs_, runs_);
  } catch (...) {
  }
}

Outcome dispatch_ensemble(const Graph& g, GraphInstance& aggregate, const RunOptions& opt, std::uint64_t runs,
                          Transport& transport) {
  Outcome out = empty_outcome(g, runs);
  const NodeLabels labels = labels_of(g, aggregate);
  // Streaming sinks (sink.csv) write into --out as they merge, on whichever thread merges; this
  // thread merges results received from other processes, and runs finish().
  OutputDirectoryScope dir(opt.output_dir);
  const std::uint64_t window = transport.window(out.warnings);
  RunDispatcher d(
      runs, window, [&](std::uint64_t run, RunRecord&& rec) { merge_run(aggregate, labels, run, runs, std::move(rec), out); },
      opt.progress, [&](std::optional<std::uint64_t> run, std::exception_ptr e) { return transport.attribute(run, e); },
      out.warnings);
  const auto t0 = std::chrono::steady_clock::now();
  transport.carry(d);
  d.conclude();
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  finish_all(g, aggregate, labels, opt, runs, out);
  return out;
}

}  // namespace trackflow::host
