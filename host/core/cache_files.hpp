#pragma once
// What the on-disk caches (the bench's float64 references, the Vulkan pipeline cache) share:
// their folder and a cheap content hash for their keys (not a cryptographic one).
#include <cstddef>
#include <cstdint>
#include <string>

namespace dacrt {

std::uint64_t fnv1a(const void* data, std::size_t bytes, std::uint64_t seed = 1469598103934665603ull);
std::string hex16(std::uint64_t h);
// $XDG_CACHE_HOME/dacrt, else ~/.cache/dacrt, else .dacrt-cache.
std::string defaultCacheDir();

}  // namespace dacrt
