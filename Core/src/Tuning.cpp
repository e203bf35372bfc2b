// The test-only fault injection of Tuning.h (process-wide switches, off by default).
#include "spaceskip/Tuning.h"

#include <atomic>

namespace spaceskip::testing {

namespace {
std::atomic<int64_t> memoryLimit{-1};
std::atomic<bool> failRenderOn{false};
}  // namespace

void setDeviceMemoryLimit(int64_t bytes) { memoryLimit.store(bytes < 0 ? -1 : bytes, std::memory_order_relaxed); }
int64_t deviceMemoryLimit() { return memoryLimit.load(std::memory_order_relaxed); }
void setFailRender(bool on) { failRenderOn.store(on, std::memory_order_relaxed); }
bool failRender() { return failRenderOn.load(std::memory_order_relaxed); }

}  // namespace spaceskip::testing
