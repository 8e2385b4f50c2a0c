#pragma once
// The float64 reference frames a bench run compares against, cached on disk across runs.
#include <cstdint>
#include <string>
#include <vector>

#include "core/cache_files.hpp"
#include "core/camera.hpp"
#include "core/scene.hpp"
#include "core/thread_pool.hpp"
#include "oracle/reference_tracer.hpp"

namespace dacrt {

// FNV-1a of the bytes and their count: a cache key part, not a cryptographic hash.
std::string digestOf(const void* data, std::size_t bytes);
std::string cameraKey(const Camera& c, int width, int height);

// The cache key of one camera's reference frame.
std::string referenceKey(const std::string& trianglesDigest, const std::vector<Ray>& rays, const Camera& camera,
                         int width, int height);

// The float64 reference of one camera, read from cacheDir when it holds one for `key`, else
// traced (and stored there). An empty cacheDir means no cache.
std::vector<ReferenceHit> cachedReference(const Scene& scene, const std::vector<Ray>& rays, const std::string& key,
                                          const std::string& cacheDir, ThreadPool& pool);

}  // namespace dacrt
