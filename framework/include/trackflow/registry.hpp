// Purpose: how a plugin declares its component types (kind, ports, parameters, factory) to the host.
#pragma once

#include <trackflow/component.hpp>
#include <trackflow/estimator.hpp>
#include <trackflow/params.hpp>

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace trackflow {

// Tracker: a node from scans to track sets. Associator, Initiator, Deleter: the parts of a tracker
// (tracker.hpp), only ever given as its nested `{type: ...}` parameters, never as nodes.
enum class ComponentKind { Source, Converter, Filter, Adapter, Sink, Tracker, Associator, Initiator, Deleter };
const char* to_string(ComponentKind k);

// Declaration of one component type, separate from any pipeline that uses it.
struct ComponentDecl {
  std::string type;          // "filter.kalman"
  ComponentKind kind = ComponentKind::Filter;
  std::string summary;       // one line
  std::string doc;           // optional paragraph: equations, sources
  std::vector<ParamSpec> params;
  ItemMask accepts = 0;      // item kinds accepted on inputs
  int min_inputs = 1;
  int max_inputs = 1;        // -1: unbounded
  ItemMask produces = 0;     // item kinds emitted
  // Measurement frames (items.hpp) accepted on inputs and produced; the graph refuses a wire
  // whose frames do not meet (e.g. spherical radar output into a Cartesian-only filter).
  FrameMask accepts_frames = kAnyFrame;
  FrameMask produces_frames = kAnyFrame;
  // A source whose items come in non-decreasing time within a run (out-of-order ones refused or
  // skipped); its consumers learn it through InputInfo::time_ordered.
  bool time_ordered = false;
  // Its instances gather the items of one instant and emit them from Component::on_time_complete
  // (a scan radar); the engine calls that only on nodes that set this.
  bool groups_by_time = false;
  std::function<std::unique_ptr<Component>(const Params&)> create;
  // A filter whose state estimator runs per track (estimator.hpp): the same parameters make the
  // estimator alone, which a tracker (or filter.imm, as a mode) clones for each track it starts.
  std::function<std::unique_ptr<Estimator>(const Params&)> create_estimator;
  // A tracker part (kind Associator, Initiator or Deleter): made from its parameters by the
  // tracker that names it (make_part in tracker.hpp); `create` stays empty.
  std::function<std::unique_ptr<TrackerPart>(const Params&)> create_part;
};

class Registrar {
 public:
  virtual ~Registrar() = default;
  virtual void add(ComponentDecl decl) = 0;
};

}  // namespace trackflow
