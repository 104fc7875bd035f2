// Purpose: every per-run result of every pipeline in pipelines/ crosses the RunResultCodec round trip exactly (what mpirun relies on), without MPI: a node that returns a result without the codec fails, and merging the decoded results gives the same summary and files as merging the originals.
#include <trackflow/host/config.hpp>
#include <trackflow/host/filter_control.hpp>
#include <trackflow/host/graph.hpp>
#include <trackflow/host/guard.hpp>
#include <trackflow/rng.hpp>
#include <trackflow/run_result_codec.hpp>

#include <catch2/catch.hpp>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "plugin_fixture.hpp"

using namespace trackflow;
using namespace trackflow::host;
namespace fs = std::filesystem;

namespace {

// A folder of this test process, removed when the process exits.
const fs::path& scratch_root() {
  struct Root {
    fs::path path = fs::temp_directory_path() / ("trackflow_test_codecs_" + std::to_string(::getpid()));
    ~Root() {
      std::error_code ec;
      fs::remove_all(path, ec);
    }
  };
  static const Root root;
  return root.path;
}

std::string slurp(const fs::path& p) {
  std::ifstream is(p, std::ios::binary);
  std::stringstream ss;
  ss << is.rdbuf();
  return ss.str();
}

// The same number, bit for bit (NaN payloads included): merged sums must not differ by an ulp.
bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// Everything a node's summary says, numbers as their bit patterns; file paths relative to `dir`.
std::string describe(const Summary& s, const fs::path& dir) {
  std::ostringstream os;
  os.precision(17);
  for (const auto& m : s.metrics) {
    std::uint64_t bits[4];
    std::memcpy(&bits[0], &m.value, 8);
    std::memcpy(&bits[1], &m.band_lo, 8);
    std::memcpy(&bits[2], &m.band_hi, 8);
    std::memcpy(&bits[3], &m.confidence, 8);
    os << "metric " << m.name << " = " << m.value << " [" << bits[0] << "] " << m.unit << " band " << m.has_band << " "
       << bits[1] << " " << bits[2] << " " << bits[3] << "\n";
  }
  for (const auto& n : s.notes) os << "note " << n << "\n";
  for (const auto& f : s.files) os << "file " << fs::relative(f, dir).string() << "\n";
  for (const auto& series : s.series) {
    os << "series " << series.name << " " << series.description << " " << series.columns.size() << " "
       << series.values.size() << "\n";
    for (const auto& c : series.columns) os << "  column " << c.name << " " << c.unit << "\n";
    std::uint64_t h = 1469598103934665603ull;  // the values' bit patterns, hashed
    for (double v : series.values) {
      std::uint64_t b;
      std::memcpy(&b, &v, 8);
      h = (h ^ b) * 1099511628211ull;
    }
    os << "  values " << h << "\n";
  }
  return os.str();
}

// As the engines do it: the generator with the earliest next item goes first.
void drive(GraphInstance& inst) {
  std::vector<Generator*> gens;
  for (int r : inst.roots) gens.push_back(static_cast<Generator*>(inst.components[static_cast<size_t>(r)].get()));
  for (;;) {
    Generator* best = nullptr;
    double t = std::numeric_limits<double>::infinity();
    for (Generator* g : gens)
      if (g->next_time() < t) {
        t = g->next_time();
        best = g;
      }
    if (!best) return;
    best->emit_next();
  }
}

struct Finished {
  std::vector<std::string> summaries;  // by node; "error: ..." when finish() threw
  std::vector<std::pair<std::string, std::string>> files;  // (relative path, bytes) under the output folder
};

Finished finish_all(GraphInstance& aggregate, const Graph& g, const fs::path& dir, std::uint64_t runs) {
  Finished f;
  const std::string out = dir.string();
  OutputDirectoryScope scope(out);
  for (size_t i = 0; i < aggregate.components.size(); ++i) {
    Summary s;
    try {
      aggregate.components[i]->finish(s, {g.nodes[i].config.id, out, runs});
      f.summaries.push_back(describe(s, dir));
    } catch (const std::exception& e) {
      f.summaries.push_back(std::string("error: ") + e.what());
    }
  }
  if (fs::exists(dir))
    for (const auto& e : fs::recursive_directory_iterator(dir))
      if (e.is_regular_file()) f.files.emplace_back(fs::relative(e.path(), dir).string(), slurp(e.path()));
  std::sort(f.files.begin(), f.files.end());
  return f;
}

// Runs `runs` runs of `file` on one instance; every result is merged as it is into one
// aggregating instance and, after save -> load on a third instance, into another.
void check_pipeline(const fs::path& file, std::uint64_t runs) {
  INFO("pipeline " << file.filename().string());
  const PluginRegistry& reg = test::registry();
  PipelineConfig cfg = parse_pipeline(load_yaml_file(file.string()), file.string());
  const Graph g = build_graph(cfg, reg);
  GraphInstance inst = instantiate(g, reg);
  GraphInstance direct = instantiate(g, reg);
  GraphInstance decoded = instantiate(g, reg);
  const fs::path dir = scratch_root() / file.stem();
  const std::string work = (dir / "work").string(), direct_dir = (dir / "direct").string(),
                    decoded_dir = (dir / "decoded").string();
  std::vector<Filter*> filters;
  for (auto& c : inst.components)
    if (auto* f = dynamic_cast<Filter*>(c.get())) filters.push_back(f);
  const size_t N = g.nodes.size();
  int codecs_used = 0;
  for (std::uint64_t run = 0; run < runs; ++run) {
    Diagnostics diag;
    std::vector<std::unique_ptr<RunResult>> results(N);
    {
      OutputDirectoryScope scope(work);  // where sink.csv spills a large run
      for (Filter* f : filters) host::FilterControl::reset_adapted_state(*f);
      for (size_t i = 0; i < N; ++i)
        inst.components[i]->start_run({run, derive_seed(cfg.seed, run, g.nodes[i].config.id), &diag});
      drive(inst);
      for (size_t i = 0; i < N; ++i) results[i] = inst.components[i]->end_run();
    }
    for (size_t i = 0; i < N; ++i) {
      if (!results[i]) continue;
      INFO("node '" << g.nodes[i].config.id << "' (" << g.nodes[i].config.type << "), run " << run);
      const auto* codec = dynamic_cast<const RunResultCodec*>(inst.components[i].get());
      // Without it the node cannot run under mpirun: the MPI engine refuses the pipeline.
      REQUIRE(codec != nullptr);
      std::string bytes;
      ByteWriter w(bytes);
      codec->save_run_result(*results[i], w);
      std::unique_ptr<RunResult> loaded;
      {
        OutputDirectoryScope scope(decoded_dir);
        ByteReader in(bytes.data(), bytes.size());
        loaded = dynamic_cast<const RunResultCodec&>(*decoded.components[i]).load_run_result(in);
        CHECK(in.done());  // read exactly what was written
      }
      REQUIRE(loaded != nullptr);
      // Written again, the decoded result gives the same bytes.
      std::string again;
      ByteWriter w2(again);
      codec->save_run_result(*loaded, w2);
      CHECK(again == bytes);
      {
        OutputDirectoryScope scope(direct_dir);
        direct.components[i]->merge(*results[i]);
      }
      {
        OutputDirectoryScope scope(decoded_dir);
        decoded.components[i]->merge(*loaded);
      }
      ++codecs_used;
    }
  }
  const Finished a = finish_all(direct, g, direct_dir, runs);
  const Finished b = finish_all(decoded, g, decoded_dir, runs);
  for (size_t i = 0; i < N; ++i) {
    INFO("node '" << g.nodes[i].config.id << "' (" << g.nodes[i].config.type << ")");
    CHECK(b.summaries[i] == a.summaries[i]);
  }
  REQUIRE(a.files.size() == b.files.size());
  for (size_t k = 0; k < a.files.size(); ++k) {
    INFO("file " << a.files[k].first);
    CHECK(b.files[k].first == a.files[k].first);
    CHECK(b.files[k].second == a.files[k].second);  // byte-identical
  }
  CHECK(codecs_used > 0);
}

std::vector<fs::path> pipelines() {
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(fs::path(TRACKFLOW_SOURCE_DIR) / "pipelines"))
    if (e.path().extension() == ".yaml") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  return files;
}

}  // namespace

// Two runs of each pipeline: every node with a per-run result implements the codec, decodes
// exactly what it wrote, and merged decoded results finish as the originals do.
TEST_CASE("every pipeline's per-run results survive the codec exactly") {
  const auto files = pipelines();
  REQUIRE(files.size() >= 10);
  for (const auto& f : files) check_pipeline(f, 2);
}

// One number per kind of value: doubles arrive bit for bit (NaN, -0, denormals, extremes).
TEST_CASE("the byte writer and reader keep doubles bit for bit") {
  const double values[] = {0.1, -0.0, std::numeric_limits<double>::quiet_NaN(),
                           std::numeric_limits<double>::denorm_min(), std::numeric_limits<double>::infinity(),
                           -std::numeric_limits<double>::max(), 1.0 / 3.0};
  std::string bytes;
  ByteWriter w(bytes);
  for (double v : values) w.put(v);
  w.put_string("tail");
  ByteReader in(bytes.data(), bytes.size());
  for (double v : values) CHECK(same_bits(in.get<double>(), v));
  CHECK(in.get_string() == "tail");
  CHECK(in.done());
  ByteReader truncated(bytes.data(), bytes.size() - 1);
  for (size_t k = 0; k < std::size(values); ++k) truncated.get<double>();
  CHECK_THROWS_AS(truncated.get_string(), DataError);
}
