#include "peers/embree_tracer.hpp"

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <map>
#include <mutex>
#include <stdexcept>
#include <string>

#include <embree3/rtcore.h>

#include "core/timing.hpp"
#include "peers/embree_memory.hpp"
#include "peers/embree_packets.hpp"

namespace dacrt {

namespace {

// Large enough that the pool's hand-out of indices costs nothing next to the rays, small
// enough that a frame of a few hundred thousand rays still balances over the threads.
// Whole 16-wide packets, so that only a frame's last packet runs partly empty.
constexpr std::size_t kRaysPerChunk = 4096;
static_assert(kRaysPerChunk % 16 == 0);

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
// after TBB's own teardown. Held through a pointer that is never destroyed either, so that
// they stay reachable to the end (LeakSanitizer checks after static destruction).
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

    // What the device's structures hold now, and the most since markPeak: Embree reports each
    // allocation before it is made and each release after it, from any of its threads.
    std::atomic<std::int64_t> bytes{0}, peakBytes{0};

    static bool countBytes(void* self, ssize_t change, bool) {
        SharedDevice& d = *static_cast<SharedDevice*>(self);
        const std::int64_t now = d.bytes.fetch_add(change) + change;
        std::int64_t peak = d.peakBytes.load();
        while (now > peak && !d.peakBytes.compare_exchange_weak(peak, now)) {
        }
        return true;  // counted, never refused: the bench plans before it builds (peers/embree_memory.hpp)
    }
    std::int64_t markPeak() {
        const std::int64_t now = bytes.load();
        peakBytes.store(now);
        return now;
    }
};

SharedDevice& sharedDevice(unsigned threads) {
    static std::mutex mutex;
    static auto* const devices = new std::map<unsigned, SharedDevice*>;
    std::lock_guard<std::mutex> lock(mutex);
    SharedDevice*& slot = (*devices)[threads];
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
        rtcSetDeviceMemoryMonitorFunction(device, &SharedDevice::countBytes, slot);
    }
    return *slot;
}

// The identity index buffer of n triangles stored as 3n consecutive vertices, made once per
// count and shared by every scene of that count: a renderer keeps its topology's indices.
const std::vector<std::uint32_t>& identityIndices(std::size_t triangles) {
    static std::mutex mutex;
    static std::map<std::size_t, std::vector<std::uint32_t>> cache;
    std::lock_guard<std::mutex> lock(mutex);
    std::vector<std::uint32_t>& v = cache[triangles];
    if (v.size() != triangles * 3) {
        v.resize(triangles * 3);
        for (std::size_t i = 0; i < v.size(); ++i) v[i] = std::uint32_t(i);
    }
    return v;
}

RTCBuildQuality geometryQualityOf(EmbreeBuild build) {
    switch (build) {
        case EmbreeBuild::Dynamic: return RTC_BUILD_QUALITY_LOW;
        case EmbreeBuild::Refit: return RTC_BUILD_QUALITY_REFIT;
        case EmbreeBuild::Static: return RTC_BUILD_QUALITY_HIGH;
    }
    return RTC_BUILD_QUALITY_MEDIUM;
}

// dacrt's face rule (shaders/triangle_rules.glsl) as Embree 3 users apply it without a build
// of their own (EMBREE_BACKFACE_CULLING is a compile-time option, off in Debian's): an
// intersection and occluded filter that rejects the back faces of single-sided triangles. Called only for
// candidate hits, so a frame pays for it per hit found, not per test.
void rejectCulledBackFaces(const RTCFilterFunctionNArguments* args) {
    const auto& triangles = *static_cast<const std::vector<Triangle>*>(args->geometryUserPtr);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] == 0) continue;
        const Triangle& t = triangles[RTCHitN_primID(args->hit, args->N, i)];
        if (!t.cullBackFace) continue;
        const glm::dvec3 n = glm::cross(glm::dvec3(t.v1) - glm::dvec3(t.v0), glm::dvec3(t.v2) - glm::dvec3(t.v0));
        const glm::dvec3 d(RTCRayN_dir_x(args->ray, args->N, i), RTCRayN_dir_y(args->ray, args->N, i),
                           RTCRayN_dir_z(args->ray, args->N, i));
        if (glm::dot(n, d) >= 0.0) args->valid[i] = 0;
    }
}

}  // namespace

struct EmbreeScene::Impl {
    SharedDevice* shared = nullptr;
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    RTCGeometry geometry = nullptr;  // owned by the scene once attached
    EmbreeOptions options;

    Impl() = default;
    Impl(const Impl&) = delete;
    Impl& operator=(const Impl&) = delete;

    // Owns the scene from the moment it exists, so a constructor that throws halfway still
    // releases it (~EmbreeScene does not run then).
    ~Impl() {
        if (scene) rtcReleaseScene(scene);
    }

    // The error code is per thread, so this reports failures of calls made on this thread.
    std::string pendingError(const char* call) const {
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

    // Rays [begin, end) that are not an image: packets of 16 consecutive rays, or single rays.
    void traceRun(const std::vector<Ray>& rays, std::size_t begin, std::size_t end, HitQuery query,
                  std::vector<Hit>& hits) const;
};

EmbreeScene::EmbreeScene(const std::vector<Triangle>& triangles, const EmbreeOptions& options)
    : impl_(std::make_unique<Impl>()) {
    impl_->shared = &sharedDevice(options.threads);
    impl_->device = impl_->shared->device;
    impl_->options = options;

    // Only what a new frame repeats is timed: the scene, its geometry and the BVH build.
    const std::int64_t bytesBefore = impl_->shared->markPeak();
    const Clock::time_point start = Clock::now();
    impl_->scene = rtcNewScene(impl_->device);
    impl_->check("rtcNewScene");
    int flags = options.robust ? RTC_SCENE_FLAG_ROBUST : RTC_SCENE_FLAG_NONE;
    if (options.build != EmbreeBuild::Static) flags |= RTC_SCENE_FLAG_DYNAMIC;
    rtcSetSceneFlags(impl_->scene, RTCSceneFlags(flags));
    impl_->check("rtcSetSceneFlags");
    rtcSetSceneBuildQuality(impl_->scene, options.build == EmbreeBuild::Static ? RTC_BUILD_QUALITY_HIGH : RTC_BUILD_QUALITY_LOW);
    impl_->check("rtcSetSceneBuildQuality");

    // An empty list has nothing to attach: the committed empty scene is one every ray misses.
    if (!triangles.empty()) {
        GeometryHandle geometry(rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_TRIANGLE));
        impl_->check("rtcNewGeometry");
        // The scene's quality picks the top-level builder only; each mesh is built at its own
        // quality, which defaults to MEDIUM (SAH). LOW selects the Morton builder that dynamic
        // scenes are meant to use (4x faster on the Dragon), REFIT keeps the topology's tree.
        rtcSetGeometryBuildQuality(geometry.get(), geometryQualityOf(options.build));
        impl_->check("rtcSetGeometryBuildQuality");
        // dacrt's Triangle is three 16-byte vertex slots (a float3 and padding each), so the
        // array is a vertex buffer of stride 16 as it is, and every 16-byte load Embree makes
        // stays inside it. The index buffer is the identity: primID is the triangle's index.
        rtcSetSharedGeometryBuffer(geometry.get(), RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, triangles.data(), 0,
                                   16, triangles.size() * 3);
        impl_->check("rtcSetSharedGeometryBuffer(vertex)");
        rtcSetSharedGeometryBuffer(geometry.get(), RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                   identityIndices(triangles.size()).data(), 0, 3 * sizeof(std::uint32_t),
                                   triangles.size());
        impl_->check("rtcSetSharedGeometryBuffer(index)");
        if (options.faceFilter && singleSidedTriangles(triangles) > 0) {
            rtcSetGeometryUserData(geometry.get(), const_cast<std::vector<Triangle>*>(&triangles));
            // Embree 3 calls a geometry's intersection filter from rtcIntersect only and its
            // occluded filter from rtcOccluded only: the face rule needs both.
            rtcSetGeometryIntersectFilterFunction(geometry.get(), &rejectCulledBackFaces);
            impl_->check("rtcSetGeometryIntersectFilterFunction");
            rtcSetGeometryOccludedFilterFunction(geometry.get(), &rejectCulledBackFaces);
            impl_->check("rtcSetGeometryOccludedFilterFunction");
        }
        rtcCommitGeometry(geometry.get());
        impl_->check("rtcCommitGeometry");
        rtcAttachGeometry(impl_->scene, geometry.get());
        impl_->check("rtcAttachGeometry");
        impl_->geometry = geometry.get();  // the scene now holds its own reference; ours is released
    }

    rtcCommitScene(impl_->scene);
    impl_->check("rtcCommitScene");
    buildMs_ = msSince(start);
    memory_.held = std::uint64_t(std::max<std::int64_t>(0, impl_->shared->bytes.load() - bytesBefore));
    memory_.buildPeak = std::uint64_t(std::max<std::int64_t>(0, impl_->shared->peakBytes.load() - bytesBefore));
}

EmbreeScene::~EmbreeScene() = default;

double EmbreeScene::update() {
    const Clock::time_point start = Clock::now();
    if (impl_->geometry) {
        rtcUpdateGeometryBuffer(impl_->geometry, RTC_BUFFER_TYPE_VERTEX, 0);
        impl_->check("rtcUpdateGeometryBuffer");
        rtcCommitGeometry(impl_->geometry);
        impl_->check("rtcCommitGeometry");
    }
    rtcCommitScene(impl_->scene);
    impl_->check("rtcCommitScene");
    return msSince(start);
}

RTCSceneTy* EmbreeScene::handle() const { return impl_->scene; }

std::string EmbreeScene::pendingError(const char* call) const { return impl_->pendingError(call); }

void EmbreeScene::Impl::traceRun(const std::vector<Ray>& rays, std::size_t begin, std::size_t end, HitQuery query,
                                 std::vector<Hit>& hits) const {
    const bool any = query == HitQuery::Any;
    if (!options.packets) {
        for (std::size_t i = begin; i < end; ++i)
            hits[i] = any ? embree::occluded1(scene, embree::laneRayOf(rays[i]))
                          : embree::intersect1(scene, embree::laneRayOf(rays[i]));
        return;
    }
    // Rays that are not an image (secondary rays leave surfaces every way) have no
    // neighbourhood to exploit: no coherent flag. The last packet's missing lanes trace a
    // copy of its first ray, masked out.
    for (std::size_t first = begin; first < end; first += 16) {
        embree::Packet16 packet;
        for (std::size_t l = 0; l < 16; ++l) {
            const bool inside = first + l < end;
            packet.valid[l] = inside ? -1 : 0;
            packet.rays[l] = embree::laneRayOf(rays[inside ? first + l : first]);
        }
        Hit answers[16];
        if (any) embree::occluded16(scene, packet, false, answers);
        else embree::intersect16(scene, packet, false, answers);
        for (std::size_t l = 0; l < 16 && first + l < end; ++l) hits[first + l] = answers[l];
    }
}

TraceResult EmbreeScene::trace(const std::vector<Ray>& rays, ThreadPool& pool, HitQuery query,
                               std::optional<std::uint32_t> imageWidth) const {
    TraceResult result;
    result.hits.resize(rays.size());
    result.threads = pool.size();
    result.regions = 1;
    result.axis = -1;

    const bool packets = impl_->options.packets, any = query == HitQuery::Any;
    const char* call = packets ? (any ? "rtcOccluded16" : "rtcIntersect16") : (any ? "rtcOccluded1" : "rtcIntersect1");
    auto pendingError = [&] { return impl_->pendingError(call); };
    const Clock::time_point start = Clock::now();
    const std::size_t width = imageWidth.value_or(impl_->options.imageWidth);
    if (packets && width != 0 && !rays.empty()) {
        // The image's 4x4 pixel tiles: rays of one camera through neighbouring pixels, what the
        // coherent flag is for.
        embree::traceTiles(
            width, rays.size(), pool,
            [&](const embree::Tile& tile) {
                embree::traceTile(impl_->scene, tile, query,
                                  [&](int l) { return embree::laneRayOf(rays[tile.index[l]]); }, result.hits.data());
            },
            pendingError);
    } else {
        const std::size_t chunks = (rays.size() + kRaysPerChunk - 1) / kRaysPerChunk;
        embree::FirstFailure failure;
        pool.parallelFor(chunks, [&](std::size_t chunk, unsigned) {
            const embree::FlushDenormals ftz;
            const std::size_t begin = chunk * kRaysPerChunk, end = std::min(rays.size(), begin + kRaysPerChunk);
            impl_->traceRun(rays, begin, end, query, result.hits);
            failure.keepError(pendingError());
        });
        failure.rethrow();
    }
    result.phases.trace = msSince(start);
    return result;
}

MemoryPlan embreePlan(const FrameGeometry& geometry) {
    MemoryPlan plan;
    // Embree allocates its structure itself: the line is a bound from the triangle count.
    plan.add(kEmbreeStructurePlanLine, embreeStructureBytesBound(geometry.triangles->size()));
    plan.add("triangles (Embree's vertex buffer, shared)", geometry.triangles->size() * sizeof(Triangle));
    plan.add("hits", geometry.rays->size() * sizeof(Hit));
    plan.addWork("rays", geometry.rays->size(), "traced by Embree");
    return plan;
}

TraceResult traceEmbree(const FrameGeometry& geometry, const EmbreeOptions& options, ThreadPool& pool) {
    const EmbreeScene scene(*geometry.triangles, options);
    TraceResult result = scene.trace(*geometry.rays, pool, geometry.query, geometry.imageWidth);
    result.phases.build = scene.buildMs();
    return result;
}

}  // namespace dacrt
