// Purpose: how a nested adapter entry's factory travels in NestedComponent::part_factory (an adapter wrapped as a tracker part), set by the host's validation and unwrapped by NestedComponent::create_adapter.
#pragma once

#include <trackflow/component.hpp>
#include <trackflow/tracker.hpp>

#include <boost/config.hpp>

#include <memory>

namespace trackflow::host {

// An adapter made by its type's ComponentDecl::create, carried as a TrackerPart: NestedComponent
// has no field for a component factory, and adding one would change its layout (the plugin ABI).
struct BOOST_SYMBOL_VISIBLE AdapterPart final : TrackerPart {
  std::unique_ptr<Component> adapter;
};

}  // namespace trackflow::host
