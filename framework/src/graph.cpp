// Purpose: graph construction and checks (types, parameters, wiring, cycles) and per-thread instantiation.
#include <trackflow/host/graph.hpp>
#include <trackflow/host/filter_control.hpp>
#include <trackflow/host/guard.hpp>
#include <trackflow/host/output_names.hpp>
#include <trackflow/host/suggest.hpp>
#include <trackflow/names.hpp>
#include <trackflow/host/validate.hpp>
#include <trackflow/track_adapters.hpp>

#include <algorithm>
#include <functional>
#include <map>
#include <new>
#include <queue>

namespace trackflow::host {
namespace {

std::string kinds(ItemMask m) {
  std::vector<std::string> k;
  for (ItemKind i : kItemKinds)
    if (m & mask(i)) k.push_back(to_string(i));
  return k.empty() ? "nothing" : join(k, "/");
}

}  // namespace

std::string unknown_type_message(const std::string& type, const PluginRegistry& reg) {
  const auto names = reg.type_names();
  const std::string suggestion = did_you_mean(type, names);
  std::string m = "unknown type '" + quote_token(type) + "'" + suggestion + ". Available: " +
                  (names.empty() ? "none" : join(names)) + ". Searched: " + join(reg.searched());
  // Not a typo of ours: most likely a third-party plugin whose folder was not given (issue 26).
  if (suggestion.empty())
    m += ". A type from another plugin: give its folder with --plugin-path DIR (or TRACKFLOW_PLUGIN_PATH)";
  for (const auto& p : reg.problems()) m += "\n  plugin not loaded: " + p.str();
  std::vector<std::string> ignored = reg.ignored();
  std::sort(ignored.begin(), ignored.end());
  for (const auto& f : ignored)
    m += "\n  not loaded: '" + quote_token(f) + "' (plugin files are named tfplugin_<name>.so)";
  return m;
}

Graph build_graph(PipelineConfig cfg, const PluginRegistry& registry) {
  // What validation (a declaration's plausible range) and construction (Params::warn) find valid
  // but seldom meant is collected here, for the CLI to print before anything runs.
  std::vector<std::string> warnings;
  struct Uninstall {
    std::vector<std::string>* previous;
    ~Uninstall() { trackflow::detail::install_setup_warnings(previous); }
  } uninstall{trackflow::detail::install_setup_warnings(&warnings)};
  Graph g;
  g.config = std::move(cfg);
  std::map<std::string, int> index;
  std::vector<std::string> ids;
  for (size_t i = 0; i < g.config.nodes.size(); ++i) {
    index[g.config.nodes[i].id] = static_cast<int>(i);
    ids.push_back(g.config.nodes[i].id);
  }
  bool sites_used = false;
  ComponentTypes types;  // what Component parameters may name
  for (const auto& t : registry.types()) types.push_back(&t.decl);
  for (const auto& nc : g.config.nodes) {
    GraphNode n;
    n.config = nc;
    n.type = registry.find(nc.type);
    if (!n.type) throw ConfigError(unknown_type_message(nc.type, registry), nc.type_loc, nc.id);
    const ComponentDecl& d = n.type->decl;
    if (d.kind == ComponentKind::Associator || d.kind == ComponentKind::Initiator || d.kind == ComponentKind::Deleter)
      throw ConfigError(quote_token(nc.type) + " is a tracker's " + to_string(d.kind) + ", not a node: give it inside a tracker, e.g. " +
                            std::string(to_string(d.kind)) + ": { type: " + nc.type + ", ... } in tracker.multi's params",
                        nc.type_loc, nc.id);
    // Pipeline-wide settings (on_bad_row, sites, frame_origin) apply to every node that declares the
    // parameter and does not set it itself.
    Value params = nc.params;
    auto declares = [&](const char* name) {
      return std::any_of(d.params.begin(), d.params.end(), [&](const ParamSpec& s) { return s.name == name; });
    };
    auto inject = [&](const char* name, const Value& v, const SourceLoc& key_loc) {
      if (!declares(name) || params.find(name)) return;
      if (params.kind != Value::Kind::Map) params.kind = Value::Kind::Map;
      params.entries.emplace_back(name, v);
      params.key_locs.push_back(key_loc);
    };
    Value bad_row;
    bad_row.kind = Value::Kind::Scalar;
    bad_row.scalar = g.config.on_bad_row;
    bad_row.loc = params.loc;
    inject("on_bad_row", bad_row, params.loc);
    if (g.config.sites.kind == Value::Kind::List) {
      sites_used |= declares("sites");
      inject("sites", g.config.sites, g.config.sites.loc);
    }
    if (g.config.frame_origin.is_scalar()) inject("frame_origin", g.config.frame_origin, g.config.frame_origin.loc);
    n.params = validate_params(d.params, params, nc.id, nc.loc, types);
    for (size_t k = 0; k < nc.inputs.size(); ++k) {
      const auto& in = nc.inputs[k];
      auto it = index.find(in);
      if (it == index.end())
        throw ConfigError("input '" + quote_token(in) + "' is not a node" + did_you_mean(in, ids) + "; nodes: " + join_some(ids),
                          nc.input_locs[k], nc.id);
      if (in == nc.id) throw ConfigError("node takes its own output as input (a cycle)", nc.input_locs[k], nc.id);
      n.inputs.push_back(it->second);
    }
    const int count = static_cast<int>(n.inputs.size());
    if (count < d.min_inputs || (d.max_inputs >= 0 && count > d.max_inputs)) {
      std::string want = d.max_inputs < 0 ? "at least " + std::to_string(d.min_inputs)
                         : d.min_inputs == d.max_inputs
                             ? std::to_string(d.min_inputs)
                             : std::to_string(d.min_inputs) + " to " + std::to_string(d.max_inputs);
      throw ConfigError(nc.type + " takes " + want + " input(s) (" + kinds(d.accepts) + "), got " +
                            std::to_string(count),
                        nc.loc, nc.id);
    }
    if (d.kind == ComponentKind::Adapter) {
      if (nc.attach_to.empty())
        throw ConfigError("adapter needs 'attach_to: <filter id>' naming the filter it retunes", nc.loc, nc.id);
    } else if (!nc.attach_to.empty()) {
      throw ConfigError("'attach_to' is only for adapters; " + quote_token(nc.type) + " is a " + to_string(d.kind), nc.attach_loc,
                        nc.id);
    }
    g.nodes.push_back(std::move(n));
  }

  if (g.config.sites.kind == Value::Kind::List && !sites_used)
    throw ConfigError("'sites' is given but no node takes sites (e.g. sim.trajectory with earth: wgs84, sim.radar "
                      "with a site); remove it",
                      g.config.sites.loc);

  // Wiring: each input must deliver something this node accepts.
  for (auto& n : g.nodes) {
    const ComponentDecl& d = n.type->decl;
    for (size_t k = 0; k < n.inputs.size(); ++k) {
      const GraphNode& up = g.nodes[n.inputs[k]];
      const ItemMask m = up.type->decl.produces & d.accepts;
      if (m == 0)
        throw ConfigError("input '" + up.config.id + "' (" + up.config.type + ") produces " +
                              kinds(up.type->decl.produces) + ", but " + n.config.type + " accepts " +
                              kinds(d.accepts),
                          n.config.input_locs[k], n.config.id);
      n.input_kinds.push_back(m);
    }
    if (!n.config.attach_to.empty()) {
      auto it = index.find(n.config.attach_to);
      if (it == index.end())
        throw ConfigError("attach_to '" + quote_token(n.config.attach_to) + "' is not a node" + did_you_mean(n.config.attach_to, ids),
                          n.config.attach_loc, n.config.id);
      if (g.nodes[it->second].type->decl.kind != ComponentKind::Filter)
        throw ConfigError("attach_to '" + n.config.attach_to + "' is a " +
                              to_string(g.nodes[it->second].type->decl.kind) + ", not a filter",
                          n.config.attach_loc, n.config.id);
      n.attach_to = it->second;
    }
  }

  // Kahn's algorithm over consumer lists (linear in nodes + wires), taking ready nodes in
  // declaration order as before; whatever is left over lies on a cycle.
  const int N = static_cast<int>(g.nodes.size());
  std::vector<int> pending(N);
  std::vector<std::vector<int>> consumers(N);
  for (int i = 0; i < N; ++i) {
    pending[i] = static_cast<int>(g.nodes[i].inputs.size());
    for (int in : g.nodes[i].inputs) consumers[in].push_back(i);
  }
  std::vector<bool> done(N, false);
  {
    // The order the former quadratic sweep produced: repeated passes over the nodes in declaration
    // order, each taking every node whose inputs are all done. A node freed by a node later in
    // the same pass is taken in that pass when it comes after it, else in the next pass.
    std::vector<int> current, next;
    for (int i = 0; i < N; ++i)
      if (pending[i] == 0) current.push_back(i);
    std::vector<char> queued(N, 0);
    for (int i : current) queued[i] = 1;
    while (!current.empty()) {
      // `current` is sorted; nodes freed during this pass at a higher index than the node being
      // processed join this pass, the others wait for the next.
      std::priority_queue<int, std::vector<int>, std::greater<int>> pass(current.begin(), current.end());
      next.clear();
      while (!pass.empty()) {
        const int i = pass.top();
        pass.pop();
        done[i] = true;
        g.order.push_back(i);
        for (int j : consumers[i]) {
          if (--pending[j] != 0 || queued[j]) continue;
          queued[j] = 1;
          if (j > i)
            pass.push(j);
          else
            next.push_back(j);
        }
      }
      std::sort(next.begin(), next.end());
      current.swap(next);
    }
  }
  if (static_cast<int>(g.order.size()) != N) {
    // Nodes left over either lie on a cycle or sit downstream of one. Walking from any of them
    // to a left-over input must revisit a node; the walk from that node back to itself is a cycle.
    int at = 0;
    while (done[at]) ++at;
    std::vector<int> path;
    std::vector<int> seen_at(N, -1);
    while (seen_at[at] < 0) {
      seen_at[at] = static_cast<int>(path.size());
      path.push_back(at);
      for (int in : g.nodes[at].inputs)
        if (!done[in]) {
          at = in;
          break;
        }
    }
    std::vector<std::string> cyc;
    for (size_t k = path.size(); k-- > static_cast<size_t>(seen_at[at]);) cyc.push_back(g.nodes[path[k]].config.id);
    cyc.push_back(cyc.front());
    const GraphNode& first = g.nodes[at];
    throw ConfigError("the graph has a cycle: " + join(cyc, " -> ") + " (each node must come after its inputs)",
                      first.config.loc, first.config.id);
  }

  // What `run` would refuse only after all the runs, `validate` refuses now: an expect naming a
  // node that does not exist (metric names are known only once the nodes have reported).
  for (const auto& e : g.config.expects)
    for (const std::string* id : {&e.node, &e.ref_node}) {
      if (id->empty() || index.count(*id)) continue;
      throw ConfigError("expect names node '" + quote_token(*id) + "', which does not exist" + did_you_mean(*id, ids) +
                            "; nodes: " + join_some(ids),
                        e.loc);
    }

  // Plugin-side checks (segment consistency, data files) run at construction; the files the
  // sinks declare then are checked for collisions (output_names.hpp).
  std::vector<DeclaredOutput> declared;
  collect_declared_outputs(&declared);
  try {
    (void)instantiate(g, registry);
  } catch (...) {
    collect_declared_outputs(nullptr);
    throw;
  }
  collect_declared_outputs(nullptr);
  g.outputs = std::move(declared);
  check_declared_outputs(g);
  g.warnings = warnings;
  return g;
}

namespace {

// The converters that turn measurements into Cartesian ones (not, e.g., a spherical corrector).
std::vector<std::string> converter_types(const PluginRegistry& registry) {
  std::vector<std::string> out;
  for (const auto& t : registry.types())
    if (t.decl.kind == ComponentKind::Converter && (t.decl.produces_frames & mask(Frame::Cartesian)))
      out.push_back(t.decl.type);
  std::sort(out.begin(), out.end());
  return out;
}

// The installed types of `kind` that accept a frame of `frames` (for a refusal's hint).
std::vector<std::string> types_taking(const PluginRegistry& registry, ComponentKind kind, FrameMask frames) {
  std::vector<std::string> out;
  for (const auto& t : registry.types())
    if (t.decl.kind == kind && (t.decl.accepts & mask(ItemKind::Measurement)) && t.decl.accepts_frames != kAnyFrame &&
        (t.decl.accepts_frames & frames))
      out.push_back(t.decl.type);
  std::sort(out.begin(), out.end());
  return out;
}

// A measurement wire whose frames do not meet is refused before anything runs.
void check_frames(const Graph& g, const GraphInstance& inst, const PluginRegistry& registry) {
  for (size_t i = 0; i < g.nodes.size(); ++i) {
    const GraphNode& n = g.nodes[i];
    const ComponentDecl& d = n.type->decl;
    for (size_t k = 0; k < n.inputs.size(); ++k) {
      if (!(n.input_kinds[k] & mask(ItemKind::Measurement))) continue;
      const GraphNode& up = g.nodes[n.inputs[k]];
      const FrameMask produced = up.type->decl.produces_frames & inst.components[n.inputs[k]]->produced_frames();
      if (produced & d.accepts_frames) continue;
      std::string hint;
      if ((d.accepts_frames & mask(Frame::Cartesian)) && (produced & mask(Frame::Spherical)))
        hint = "; insert a converter between them (" + join(converter_types(registry)) + ")";
      else if ((d.accepts_frames & mask(Frame::Spherical)) && (produced & mask(Frame::Cartesian)))
        hint = "; wire it to the radar's spherical output instead";
      else if (const std::vector<std::string> takers = types_taking(registry, d.kind, produced); !takers.empty())
        hint = std::string("; the ") + to_string(d.kind) + "s that take them: " + join(takers);
      throw ConfigError("input '" + up.config.id + "' (" + up.config.type + ") produces " + frame_names(produced) +
                            " measurements, but " + n.config.type + " takes " + frame_names(d.accepts_frames) +
                            " measurements" + hint,
                        n.config.input_locs[k], n.config.id);
    }
  }
}

// What each wire carries once the upstream instance says which of its type's kinds it emits (a
// source.csv of detections emits scans only): a wire left with nothing is refused before anything runs.
std::vector<std::vector<ItemMask>> narrowed_input_kinds(const Graph& g, const GraphInstance& inst) {
  std::vector<std::vector<ItemMask>> out(g.nodes.size());
  for (size_t i = 0; i < g.nodes.size(); ++i) {
    const GraphNode& n = g.nodes[i];
    for (size_t k = 0; k < n.inputs.size(); ++k) {
      const GraphNode& up = g.nodes[n.inputs[k]];
      const ItemMask produced = up.type->decl.produces & inst.components[n.inputs[k]]->produced_kinds();
      const ItemMask m = n.input_kinds[k] & produced;
      if (m == 0)
        throw ConfigError("input '" + up.config.id + "' (" + up.config.type + " as configured) produces " + kinds(produced) +
                              ", but " + n.config.type + " accepts " + kinds(n.type->decl.accepts),
                          n.config.input_locs[k], n.config.id);
      out[i].push_back(m);
    }
  }
  return out;
}

std::string qualified(const std::string& adapter, const std::vector<std::string>& names, size_t i) {
  return adapter + "." + names[i];
}

}  // namespace

GraphInstance instantiate_checked(const Graph& g, const PluginRegistry& registry);

// Whatever else escapes plugin code while the graph is wired (needs(), noise(), frames) is a bug.
GraphInstance instantiate(const Graph& g, const PluginRegistry& registry) {
  try {
    return instantiate_checked(g, registry);
  } catch (const ConfigError&) {
    throw;
  } catch (const InternalError&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw;
  } catch (const std::exception& e) {
    throw InternalError(std::string("a plugin threw while the graph was wired: ") + e.what() + " (a bug in that plugin)");
  } catch (...) {
    throw InternalError("a plugin threw an exception that is not a std::exception while the graph was wired");
  }
}

GraphInstance instantiate_checked(const Graph& g, const PluginRegistry& registry) {
  GraphInstance inst;
  const size_t N = g.nodes.size();
  inst.components.resize(N);
  inst.links.resize(N);
  for (size_t i = 0; i < N; ++i) {
    const GraphNode& n = g.nodes[i];
    const std::string label = "node '" + n.config.id + "' (" + n.config.type + " from " + n.type->file + ")";
    Activity constructing{"constructing", nullptr, &label};
    ActivityScope scope(constructing);
    try {
      inst.components[i] = registry.create(*n.type, n.params);
    } catch (const ConfigError& e) {
      if (!e.node().empty()) throw;
      throw ConfigError(e.what(), e.where().line ? e.where() : n.config.loc, n.config.id);
    } catch (const DataError& e) {
      throw ConfigError(e.what(), n.config.loc, n.config.id);
    } catch (const std::bad_alloc&) {
      throw;  // out of memory is no mistake in the pipeline
    } catch (const std::exception& e) {
      // What a factory throws is most often a refusal of its parameters; it is reported with the node.
      throw ConfigError(e.what(), n.config.loc, n.config.id);
    } catch (...) {
      throw InternalError("constructing " + label + " threw an exception that is not a std::exception (a bug in that plugin)");
    }
  }
  check_frames(g, inst, registry);
  const std::vector<std::vector<ItemMask>> input_kinds = narrowed_input_kinds(g, inst);

  // Adapters first: what they need is checked against the filter, and the filter's annotation
  // names are known before its consumers learn their inputs.
  std::vector<std::vector<std::string>> annotations(N);
  // A filter's own annotations come first (e.g. filter.imm's mode probabilities).
  for (size_t i = 0; i < N; ++i) {
    auto* filter = dynamic_cast<Filter*>(inst.components[i].get());
    if (!filter) continue;
    const std::vector<std::string> names = filter->annotation_names();
    if (names.empty()) continue;
    // Annotation names become CSV columns and chart labels: the node-id rule (names.hpp), for any
    // plugin (filter.imm checks its mode names at their line already).
    for (const std::string& a : names)
      if (!is_plain_name(a))
        throw ConfigError("filter '" + g.nodes[i].config.id + "' names an annotation '" + quote_token(a) + "'; it must be " +
                              kPlainNameRule + " (it becomes a CSV column and a chart label)",
                          g.nodes[i].config.loc, g.nodes[i].config.id);
    if (!FilterControl::reserve_own_annotations(*filter, static_cast<int>(names.size())))
      throw ConfigError("filter '" + g.nodes[i].config.id + "' publishes " + std::to_string(names.size()) +
                            " annotations; at most " + std::to_string(kMaxAnnotations) + " fit on an estimate",
                        g.nodes[i].config.loc, g.nodes[i].config.id);
    for (size_t k = 0; k < names.size(); ++k) annotations[i].push_back(qualified(g.nodes[i].config.id, names, k));
  }
  // A node that runs adapters itself (a component-list parameter of kind adapter: tracker.multi's
  // per-track `adapters:`, track_adapters.hpp) carries their values on its estimates, named
  // "<node id>.<adapter type>.<name>"; it checks the adapters itself when it is made.
  for (size_t i = 0; i < N; ++i) {
    if (dynamic_cast<Filter*>(inst.components[i].get())) continue;
    for (const ParamSpec& spec : g.nodes[i].type->decl.params) {
      if (spec.type != ParamType::ComponentList || spec.kinds != std::vector<ComponentKind>{ComponentKind::Adapter})
        continue;
      for (const std::string& name : TrackAdapters::annotation_names_of(g.nodes[i].params.components(spec.name)))
        annotations[i].push_back(g.nodes[i].config.id + "." + name);
    }
  }
  for (size_t i = 0; i < N; ++i) {
    const GraphNode& n = g.nodes[i];
    if (n.attach_to < 0) continue;
    auto* adapter = dynamic_cast<Adapter*>(inst.components[i].get());
    auto* filter = dynamic_cast<Filter*>(inst.components[n.attach_to].get());
    const std::string& fid = g.nodes[n.attach_to].config.id;
    if (!adapter || !filter)
      throw ConfigError("cannot attach: " + n.config.type + " is not an Adapter or its target is not a Filter",
                        n.config.attach_loc, n.config.id);
    // The measurement frames the filter receives (its measurement wires), each of which the adapter
    // must understand: a 2-D frame reaching an adapter written for 3 values is refused here.
    const GraphNode& fn = g.nodes[n.attach_to];
    // An input that may produce any frame is checked at run time by the filter, not here.
    FrameMask incoming = 0;
    bool known = true;
    for (size_t k = 0; k < fn.inputs.size(); ++k)
      if (fn.input_kinds[k] & mask(ItemKind::Measurement)) {
        const FrameMask f = g.nodes[fn.inputs[k]].type->decl.produces_frames & inst.components[fn.inputs[k]]->produced_frames();
        known = known && f != kAnyFrame;
        incoming |= f;
      }
    if (const FrameMask refused = incoming & ~n.type->decl.accepts_frames; known && refused != 0)
      throw ConfigError("cannot attach adapter '" + n.config.id + "' (" + n.config.type + ") to filter '" + fid +
                            "': the filter receives " + frame_names(refused) + " measurements and " + n.config.type +
                            " takes " + frame_names(n.type->decl.accepts_frames) + " ones",
                        n.config.attach_loc, n.config.id);
    const NoiseNeeds needs = adapter->needs();
    if (std::string why = noise_mismatch(needs, filter->noise(), filter->has_covariance_access()); !why.empty())
      throw ConfigError("cannot attach adapter '" + n.config.id + "' (" + n.config.type + ") to filter '" + fid +
                            "' (" + g.nodes[n.attach_to].config.type + "): " + why,
                        n.config.attach_loc, n.config.id);
    const std::vector<std::string> names = adapter->annotation_names();
    if (!FilterControl::attach(*filter, *adapter, static_cast<int>(names.size())))
      throw ConfigError("too many adapters or annotations on '" + fid + "' (at most " +
                            std::to_string(Filter::kMaxAdapters) + " adapters and " + std::to_string(kMaxAnnotations) +
                            " annotations per filter)",
                        n.config.attach_loc, n.config.id);
    for (size_t k = 0; k < names.size(); ++k) annotations[n.attach_to].push_back(qualified(n.config.id, names, k));
  }

  // A node's items are in time order when every source upstream declares so: the engine merges
  // the sources by time and every other node emits as it receives (g.order: inputs first).
  std::vector<char> time_ordered(N, 0);
  for (int i : g.order) {
    const GraphNode& n = g.nodes[i];
    bool ordered = n.inputs.empty() ? n.type->decl.time_ordered : true;
    for (int up : n.inputs) ordered = ordered && time_ordered[up];
    time_ordered[i] = ordered;
  }
  for (size_t i = 0; i < N; ++i) {
    const GraphNode& n = g.nodes[i];
    std::vector<InputInfo> infos;
    for (size_t k = 0; k < n.inputs.size(); ++k) {
      const int up = n.inputs[k];
      InputInfo info{g.nodes[up].config.id, g.nodes[up].config.type, input_kinds[i][k], annotations[up]};
      if (const auto* f = dynamic_cast<const Filter*>(inst.components[up].get())) {
        info.state = f->state_layout();
        if (const TransitionModel* t = f->transition_model()) info.transition = *t;
      }
      info.time_ordered = time_ordered[up];
      infos.push_back(std::move(info));
    }
    try {
      inst.components[i]->set_inputs(infos);
    } catch (const ConfigError& e) {
      throw ConfigError(e.what(), e.where().line ? e.where() : n.config.loc, n.config.id);
    } catch (const std::exception& e) {
      throw InternalError("node '" + n.config.id + "' (" + n.config.type + " from " + n.type->file +
                          ") threw in set_inputs: " + e.what() + " (a bug in that plugin)");
    } catch (...) {
      throw InternalError("node '" + n.config.id + "' (" + n.config.type + " from " + n.type->file +
                          ") threw an exception that is not a std::exception in set_inputs (a bug in that plugin)");
    }
    for (size_t k = 0; k < n.inputs.size(); ++k)
      inst.links[n.inputs[k]].push_back({inst.components[i].get(), static_cast<int>(k), input_kinds[i][k]});
    if (n.inputs.empty() && n.type->decl.kind != ComponentKind::Adapter) {
      if (!dynamic_cast<Generator*>(inst.components[i].get()))
        throw ConfigError(n.config.type + " needs an input ('input: <node id>'); only sources can stand alone",
                          n.config.loc, n.config.id);
      inst.roots.push_back(static_cast<int>(i));
    }
  }
  for (int i : g.order)
    if (g.nodes[i].type->decl.groups_by_time) inst.time_grouping.push_back(i);
  for (size_t i = 0; i < N; ++i)
    inst.components[i]->out.connect(inst.links[i].data(), static_cast<int>(inst.links[i].size()));
  // What adapters tune is put back to this at the start of every run (engine).
  for (auto& c : inst.components)
    if (auto* f = dynamic_cast<Filter*>(c.get())) FilterControl::save_configured_noise(*f);
  return inst;
}

}  // namespace trackflow::host
