#include "bench/reference_cache.hpp"

#include <iomanip>
#include <iostream>
#include <sstream>

namespace dacrt {

// Bumped whenever the reference tracer's answers could change, so stale caches are ignored.
constexpr const char* kReferenceVersion = "reference-v2";

std::string digestOf(const void* data, std::size_t bytes) { return hex16(fnv1a(data, bytes)) + "-" + std::to_string(bytes); }

std::string cameraKey(const Camera& c, int width, int height) {
    std::ostringstream s;
    s << std::setprecision(17) << c.eye.x << "," << c.eye.y << "," << c.eye.z << "|" << c.forward.x << ","
      << c.forward.y << "," << c.forward.z << "|" << c.up.x << "," << c.up.y << "," << c.up.z << "|"
      << c.yfovRadians << "|" << int(c.projection) << "|" << c.ymag << "|" << width << "x" << height;
    return s.str();
}

// The float64 reference of one camera, read from cacheDir when it holds one for `key`, else
// traced (and stored there). An empty cacheDir means no cache.
std::vector<ReferenceHit> cachedReference(const Scene& scene, const std::vector<Ray>& rays, const std::string& key,
                                          const std::string& cacheDir, ThreadPool& pool) {
    std::vector<ReferenceHit> hits;
    const std::string path = cacheDir + "/" + hex16(fnv1a(key.data(), key.size())) + ".ref";
    if (!cacheDir.empty() && readReferenceCache(path, key, rays.size(), scene.triangleCount(), hits)) return hits;
    hits = traceReference(scene.triangles, rays, pool);
    if (cacheDir.empty()) return hits;
    try {
        writeReferenceCache(path, key, hits);
    } catch (const std::exception& e) {  // the run needs no cache, only the reference
        std::cerr << "dacrt bench: warning: reference not cached: " << e.what() << "\n";
    }
    return hits;
}

std::string referenceKey(const std::string& trianglesDigest, const std::vector<Ray>& rays, const Camera& camera,
                         int width, int height) {
    // The key holds what the reference depends on: the triangles as loaded and the rays as
    // generated (so a change to the loader or the camera code misses the cache).
    return std::string(kReferenceVersion) + "|" + trianglesDigest + "|" + digestOf(rays.data(), rays.size() * sizeof(Ray)) +
           "|" + cameraKey(camera, width, height);
}

}  // namespace dacrt
