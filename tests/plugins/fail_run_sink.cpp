// Purpose: test.fail_run — a test-only sink that fails one chosen run (a DataError at its end), to check that an MPI job stops, names the rank and the run, and exits non-zero.
#include <trackflow/plugin.hpp>

namespace {

using namespace trackflow;

class FailRun final : public Component {
 public:
  explicit FailRun(const Params& p) : run_(static_cast<std::uint64_t>(p.integer("run"))) {}
  void start_run(const RunContext& ctx) override { current_ = ctx.run; }
  void on_estimate(const Estimate&, int) override {}
  std::unique_ptr<RunResult> end_run() override {
    if (current_ == run_) throw DataError("test.fail_run: deliberate failure");
    return nullptr;
  }

 private:
  std::uint64_t run_, current_ = 0;
};

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "test.fail_run";
  d.kind = ComponentKind::Sink;
  d.summary = "Test only: throws a DataError at the end of run `run`";
  d.accepts = mask(ItemKind::Estimate);
  d.produces = 0;
  d.params = {ParamSpec::integer("run", "the run that fails").def("0")};
  d.create = [](const Params& p) -> std::unique_ptr<Component> { return std::make_unique<FailRun>(p); };
  r.add(std::move(d));
}

}  // namespace

TRACKFLOW_PLUGIN("test.fail_run", register_components)
