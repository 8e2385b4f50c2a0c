#include "oracle/embree_tracer.hpp"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <map>
#include <mutex>
#include <stdexcept>
#include <string>

#include <embree3/rtcore.h>

#include "core/timing.hpp"

namespace dacrt {

namespace {

// Large enough that the pool's hand-out of indices costs nothing next to the rays, small
// enough that a frame of a few hundred thousand rays still balances over the threads.
constexpr std::size_t kRaysPerChunk = 4096;

const char* errorName(RTCError code) {
    switch (code) {
        case RTC_ERROR_NONE: return "RTC_ERROR_NONE";
        case RTC_ERROR_UNKNOWN: return "RTC_ERROR_UNKNOWN";
        case RTC_ERROR_INVALID_ARGUMENT: return "RTC_ERROR_INVALID_ARGUMENT";
        case RTC_ERROR_INVALID_OPERATION: return "RTC_ERROR_INVALID_OPERATION";
        case RTC_ERROR_OUT_OF_MEMORY: return "RTC_ERROR_OUT_OF_MEMORY";
        case RTC_ERROR_UNSUPPORTED_CPU: return "RTC_ERROR_UNSUPPORTED_CPU";
        case RTC_ERROR_CANCELLED: return "RTC_ERROR_CANCELLED";
    }
    return "unknown RTCError";
}

struct GeometryReleaser {
    void operator()(RTCGeometry geometry) const { rtcReleaseGeometry(geometry); }
};
using GeometryHandle = std::unique_ptr<RTCGeometryTy, GeometryReleaser>;

// One Embree device per thread count for the whole process: a device is Embree's thread pool
// and ISA dispatch, which a renderer creates once, so a dynamic scene's frame must not pay
// for it. Deliberately never released: releasing it during static destruction could run
// after TBB's own teardown.
struct SharedDevice {
    RTCDevice device = nullptr;
    // Embree passes the error text only to the callback, and may call it from any thread
    // that uses the device (the pool's workers during a trace, TBB's during a commit).
    std::mutex messageMutex;
    std::string lastMessage;

    static void recordError(void* self, RTCError, const char* message) {
        SharedDevice& d = *static_cast<SharedDevice*>(self);
        std::lock_guard<std::mutex> lock(d.messageMutex);
        d.lastMessage = message ? message : "";
    }
};

SharedDevice& sharedDevice(unsigned threads) {
    static std::mutex mutex;
    static std::map<unsigned, SharedDevice*> devices;
    std::lock_guard<std::mutex> lock(mutex);
    SharedDevice*& slot = devices[threads];
    if (!slot) {
        const std::string config = threads > 0 ? "threads=" + std::to_string(threads) : "";
        RTCDevice device = rtcNewDevice(config.c_str());
        if (!device) {
            // No device, so no callback to have received a message: only the code is known.
            throw std::runtime_error(std::string("embree: rtcNewDevice: ") + errorName(rtcGetDeviceError(nullptr)) +
                                     ": device creation failed (config \"" + config + "\")");
        }
        slot = new SharedDevice;
        slot->device = device;
        rtcSetDeviceErrorFunction(device, &SharedDevice::recordError, slot);
    }
    return *slot;
}

}  // namespace

struct EmbreeScene::Impl {
    SharedDevice* shared = nullptr;
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;

    Impl() = default;
    Impl(const Impl&) = delete;
    Impl& operator=(const Impl&) = delete;

    // Owns the scene from the moment it exists, so a constructor that throws halfway still
    // releases it (~EmbreeScene does not run then).
    ~Impl() {
        if (scene) rtcReleaseScene(scene);
    }

    // The error code is per thread, so this reports failures of calls made on this thread.
    std::string pendingError(const char* call) {
        const RTCError code = rtcGetDeviceError(device);
        if (code == RTC_ERROR_NONE) return {};
        std::lock_guard<std::mutex> lock(shared->messageMutex);
        return std::string("embree: ") + call + ": " + errorName(code) + ": " +
               (shared->lastMessage.empty() ? "(no message)" : shared->lastMessage);
    }

    void check(const char* call) {
        const std::string error = pendingError(call);
        if (!error.empty()) throw std::runtime_error(error);
    }
};

EmbreeScene::EmbreeScene(const std::vector<Triangle>& triangles, const EmbreeOptions& options)
    : impl_(std::make_unique<Impl>()) {
    impl_->shared = &sharedDevice(options.threads);
    impl_->device = impl_->shared->device;

    // Only what a new frame repeats is timed: copying the triangles and the BVH build.
    const Clock::time_point start = Clock::now();
    impl_->scene = rtcNewScene(impl_->device);
    impl_->check("rtcNewScene");
    rtcSetSceneFlags(impl_->scene, options.robust ? RTC_SCENE_FLAG_ROBUST : RTC_SCENE_FLAG_NONE);
    impl_->check("rtcSetSceneFlags");
    // MEDIUM is Embree's default SAH build. HIGH adds spatial splits, several times the build
    // cost for a faster trace, which a scene rebuilt every frame does not earn back; LOW
    // (Morton) would make Embree's trace look slower than it is.
    rtcSetSceneBuildQuality(impl_->scene, RTC_BUILD_QUALITY_MEDIUM);
    impl_->check("rtcSetSceneBuildQuality");

    // An empty list has nothing to attach: the committed empty scene is one every ray misses.
    if (!triangles.empty()) {
        GeometryHandle geometry(rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_TRIANGLE));
        impl_->check("rtcNewGeometry");

        // Unindexed triangles: dacrt stores three vertices per triangle, so the index buffer
        // is the identity and primID equals the triangle's index. Buffers from
        // rtcSetNewGeometryBuffer are over-allocated by Embree for its 16-byte vertex loads,
        // so no padding is added here.
        const std::size_t vertexCount = triangles.size() * 3;
        auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(
            geometry.get(), RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), vertexCount));
        impl_->check("rtcSetNewGeometryBuffer(vertex)");
        auto* indices = static_cast<std::uint32_t*>(rtcSetNewGeometryBuffer(
            geometry.get(), RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(std::uint32_t), triangles.size()));
        impl_->check("rtcSetNewGeometryBuffer(index)");

        for (std::size_t i = 0; i < triangles.size(); ++i) {
            const Triangle& t = triangles[i];
            for (const glm::vec3* v : {&t.v0, &t.v1, &t.v2}) {
                *vertices++ = v->x;
                *vertices++ = v->y;
                *vertices++ = v->z;
            }
            for (std::uint32_t k = 0; k < 3; ++k) *indices++ = std::uint32_t(3 * i + k);
        }

        rtcCommitGeometry(geometry.get());
        impl_->check("rtcCommitGeometry");
        rtcAttachGeometry(impl_->scene, geometry.get());
        impl_->check("rtcAttachGeometry");
        // The scene now holds its own reference; the handle's release drops ours.
    }

    rtcCommitScene(impl_->scene);
    impl_->check("rtcCommitScene");
    buildMs_ = msSince(start);
}

EmbreeScene::~EmbreeScene() = default;

TraceResult EmbreeScene::trace(const std::vector<Ray>& rays, ThreadPool& pool) const {
    TraceResult result;
    result.hits.resize(rays.size());
    result.threads = pool.size();
    result.regions = 1;
    result.axis = -1;

    // The pool's workers must not throw (nothing would catch it there), so the first
    // failure is kept and thrown from this thread once every chunk is done.
    std::mutex failureMutex;
    std::string failure;

    // Embree recommends flush-to-zero and denormals-are-zero for speed; they are left off
    // because the same threads run dacrt's tracers, whose exact arithmetic they would change.
    const Clock::time_point start = Clock::now();
    const std::size_t chunks = (rays.size() + kRaysPerChunk - 1) / kRaysPerChunk;
    pool.parallelFor(chunks, [&](std::size_t chunk, unsigned) {
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        const std::size_t end = std::min(rays.size(), (chunk + 1) * kRaysPerChunk);
        for (std::size_t i = chunk * kRaysPerChunk; i < end; ++i) {
            const Ray& ray = rays[i];
            RTCRayHit query{};
            query.ray.org_x = ray.origin.x;
            query.ray.org_y = ray.origin.y;
            query.ray.org_z = ray.origin.z;
            // dacrt accepts only t > tmin while Embree's tnear is inclusive (t >= tnear). The
            // two differ only for a triangle through the point at exactly tmin, which for
            // primary rays (tmin 0) means a triangle through the eye; that case is left to
            // Embree rather than nudging tnear, which would move every other answer too.
            query.ray.tnear = ray.tmin;
            query.ray.dir_x = ray.dir.x;
            query.ray.dir_y = ray.dir.y;
            query.ray.dir_z = ray.dir.z;
            query.ray.time = 0.0f;
            query.ray.tfar = std::numeric_limits<float>::infinity();
            query.ray.mask = ~0u;
            query.ray.id = 0;
            query.ray.flags = 0;
            query.hit.geomID = RTC_INVALID_GEOMETRY_ID;
            query.hit.primID = RTC_INVALID_GEOMETRY_ID;
            query.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
            rtcIntersect1(impl_->scene, &context, &query);

            Hit& hit = result.hits[i];
            if (query.hit.geomID == RTC_INVALID_GEOMETRY_ID) {
                hit = Hit{kNoHitT, kMissPrim, 0.0f, 0.0f};
            } else {
                // Embree's u and v weight v1 and v2, as dacrt's do.
                hit = Hit{query.ray.tfar, query.hit.primID, query.hit.u, query.hit.v};
            }
        }
        const std::string error = impl_->pendingError("rtcIntersect1");
        if (!error.empty()) {
            std::lock_guard<std::mutex> lock(failureMutex);
            if (failure.empty()) failure = error;
        }
    });
    if (!failure.empty()) throw std::runtime_error(failure);
    result.phaseMs.emplace_back("trace", msSince(start));
    return result;
}

TraceResult traceEmbree(const FrameGeometry& geometry, const EmbreeOptions& options, ThreadPool& pool) {
    const EmbreeScene scene(*geometry.triangles, options);
    TraceResult result = scene.trace(*geometry.rays, pool);
    result.phaseMs.insert(result.phaseMs.begin(), {"build", scene.buildMs()});
    return result;
}

}  // namespace dacrt
