// Purpose: test.fail_run — a test-only sink that fails one chosen run, at its end or when the run is merged, with bad data or a plugin bug, to check that both engines stop and name the rank, the run and the node.
#include <trackflow/plugin.hpp>
#include <trackflow/run_result_codec.hpp>

#include <stdexcept>

namespace {

using namespace trackflow;

enum class During { EndRun, Merge };
enum class Kind { Data, Bug };

// The run a result belongs to, so that merge() can fail on the aggregating instance.
struct RunIndex final : RunResult {
  std::uint64_t run = 0;
  template <class Self, class F>
  static void fields(Self& r, F&& f) {
    f(r.run);
  }
};

class FailRun final : public Component, public FieldListCodec<RunIndex> {
 public:
  explicit FailRun(const Params& p)
      : run_(static_cast<std::uint64_t>(p.integer("run"))), during_(p.choice<During>("during")), kind_(p.choice<Kind>("kind")) {}
  void start_run(const RunContext& ctx) override { current_ = ctx.run; }
  void on_estimate(const Estimate&, int) override {}
  std::unique_ptr<RunResult> end_run() override {
    if (during_ == During::EndRun) {
      if (current_ == run_) fail();
      return nullptr;
    }
    auto r = std::make_unique<RunIndex>();
    r->run = current_;
    return r;
  }
  void merge(RunResult& r) override {
    if (static_cast<RunIndex&>(r).run == run_) fail();
  }

 private:
  [[noreturn]] void fail() const {
    if (kind_ == Kind::Data) throw DataError("test.fail_run: deliberate failure");
    throw std::logic_error("test.fail_run: deliberate bug");
  }
  std::uint64_t run_, current_ = 0;
  During during_;
  Kind kind_;
};

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "test.fail_run";
  d.kind = ComponentKind::Sink;
  d.summary = "Test only: fails run `run`, at its end or when it is merged";
  d.accepts = mask(ItemKind::Estimate);
  d.produces = 0;
  d.params = {ParamSpec::integer("run", "the run that fails").def("0"),
              ParamSpec::choice<During>("during", {{During::EndRun, "end_run"}, {During::Merge, "merge"}},
                                        "where it fails: end_run (where the run ran) or merge (on the aggregating "
                                        "instance: rank 0 under mpirun)")
                  .def("end_run"),
              ParamSpec::choice<Kind>("kind", {{Kind::Data, "data"}, {Kind::Bug, "bug"}},
                                      "data: a DataError (exit 2); bug: a std::logic_error, a plugin bug (exit 3)")
                  .def("data")};
  d.create = [](const Params& p) -> std::unique_ptr<Component> { return std::make_unique<FailRun>(p); };
  r.add(std::move(d));
}

}  // namespace

TRACKFLOW_PLUGIN("test.fail_run", register_components)
