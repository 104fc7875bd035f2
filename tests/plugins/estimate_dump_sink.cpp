// Purpose: test.estimate_dump — a test-only sink that writes a filter's full published output (state, state covariance, innovation, NIS, annotations) at 17 significant digits, for the reference-output regression test (tests/reference).
#include <trackflow/plugin.hpp>
#include <trackflow/run_result_codec.hpp>
#include <trackflow/safe_output.hpp>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace {

using namespace trackflow;

struct DumpRunResult final : RunResult {
  std::string rows;
  // Its codec under mpirun (run_result_codec.hpp).
  template <class Self, class F>
  static void fields(Self& r, F&& f) {
    f(r.rows);
  }
};

// One row per kept estimate:
//   run,step,time,initialised,updated,n,x[0..n),P upper triangle row by row,m,nu[0..m),nis,k,annotations[0..k)
// Rows of a run are kept for its first `head` estimates and then every `every`-th one (the
// errors of a filter propagate to later steps, so sampled rows still see any change), for runs
// below `runs`. Values are "%.17g": a double survives the round trip exactly.
class EstimateDump final : public Component, public FieldListCodec<DumpRunResult> {
 public:
  explicit EstimateDump(const Params& p)
      : head_(p.integer("head")), every_(p.integer("every")), runs_(p.integer("runs")) {
    if (every_ < 1) throw p.error("every", "must be at least 1");
  }

  void start_run(const RunContext& ctx) override {
    run_ = ctx.run;
    step_ = 0;
    rows_.clear();
  }

  void on_estimate(const Estimate& e, int) override {
    const long long step = step_++;
    if (static_cast<long long>(run_) >= runs_) return;
    if (step >= head_ && (step - head_) % every_ != 0) return;
    char buf[64];
    auto put = [&](double v) {
      const int n = std::snprintf(buf, sizeof buf, ",%.17g", v);
      rows_.append(buf, static_cast<size_t>(n));
    };
    rows_ += std::to_string(run_) + "," + std::to_string(step);
    put(e.time);
    rows_ += e.initialised ? ",1" : ",0";
    rows_ += e.updated ? ",1" : ",0";
    const int n = static_cast<int>(e.state.size());
    rows_ += "," + std::to_string(n);
    for (int i = 0; i < n; ++i) put(e.state(i));
    for (int i = 0; i < n; ++i)
      for (int j = i; j < n; ++j) put(e.covariance(i, j));
    const int m = static_cast<int>(e.innovation.size());
    rows_ += "," + std::to_string(m);
    for (int i = 0; i < m; ++i) put(e.innovation(i));
    put(e.nis);
    rows_ += "," + std::to_string(e.annotation_count);
    for (int i = 0; i < e.annotation_count; ++i) put(e.annotations[i]);
    rows_ += '\n';
  }

  std::unique_ptr<RunResult> end_run() override {
    auto r = std::make_unique<DumpRunResult>();
    r->rows = std::move(rows_);
    rows_.clear();
    return r;
  }

  void merge(RunResult& r) override { file_ += static_cast<DumpRunResult&>(r).rows; }

  void finish(Summary& s, const FinishContext& ctx) override {
    // As every sink's file: beneath --out without following links, renamed when whole.
    SafeOutputFile f;
    if (!f.open_beneath(ctx.output_dir.empty() ? "." : ctx.output_dir, ctx.node + ".csv") ||
        !f.write("# run,step,time,initialised,updated,n,x[n],P[i<=j],m,nu[m],nis,k,annotations[k]\n") || !f.write(file_) ||
        !f.commit())
      throw ConfigError(f.error(), {}, ctx.node);
    s.files.push_back(f.path());
  }

 private:
  long long head_, every_, runs_;
  std::uint64_t run_ = 0;
  long long step_ = 0;
  std::string rows_, file_;
};

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "test.estimate_dump";
  d.kind = ComponentKind::Sink;
  d.summary = "Test only: a filter's full output (state, covariance, innovation, NIS, annotations) at 17 digits";
  d.accepts = mask(ItemKind::Estimate);
  d.produces = 0;
  d.params = {
      ParamSpec::integer("head", "estimates kept at the start of each run").def("20"),
      ParamSpec::integer("every", "then every n-th estimate").def("10"),
      ParamSpec::integer("runs", "runs dumped (the first ones)").def("1"),
  };
  d.create = [](const Params& p) -> std::unique_ptr<Component> { return std::make_unique<EstimateDump>(p); };
  r.add(std::move(d));
}

}  // namespace

TRACKFLOW_PLUGIN("test.estimate_dump", register_components)
