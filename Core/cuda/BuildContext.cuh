// What a device builder of the registry (Builders.h) works with: the occupancy on the device,
// the stream, the tree to fill, and a workspace of its own type that the backend keeps between
// builds (so a rebuild after a TF edit reuses its device buffers).
#pragma once
#include "DeviceTree.cuh"
#include "spaceskip/Types.h"

#include <memory>
#include <typeindex>
#include <unordered_map>

namespace spaceskip::cuda {

/// Workspaces by type, owned by the backend: one per builder that asks for one.
using WorkspaceStore = std::unordered_map<std::type_index, std::shared_ptr<void>>;

struct BuildContext {
  BrickGridView grid;
  cudaStream_t stream;
  DeviceTree& tree;
  WorkspaceStore& store;

  /// The builder's workspace of type W, created on first use.
  template <class W>
  W& workspace() {
    std::shared_ptr<void>& slot = store[std::type_index(typeid(W))];
    if (!slot) slot = std::make_shared<W>();
    return *static_cast<W*>(slot.get());
  }
};

}  // namespace spaceskip::cuda
