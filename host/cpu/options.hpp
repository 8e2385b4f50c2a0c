#pragma once
// What a caller chooses: the backend and the DACRT options (defined in the public
// <dacrt/options.hpp>), with one name table each.
#include <cstdint>

#include <dacrt/backend_tuning.hpp>
#include <dacrt/options.hpp>

#include "core/enum_names.hpp"

namespace dacrt {

template <>
struct EnumNames<Backend> {
    static constexpr std::array<std::pair<Backend, std::string_view>, 6> table{{{Backend::Brute, "brute"},
                                                                                 {Backend::CpuSeq, "cpu-seq"},
                                                                                 {Backend::Cpu, "cpu"},
                                                                                 {Backend::Gpu, "gpu"},
                                                                                 {Backend::Embree, "embree"},
                                                                                 {Backend::RayQuery, "rayquery"}}};
};
template <>
struct EnumNames<SplitMethod> {
    static constexpr std::array<std::pair<SplitMethod, std::string_view>, 3> table{
        {{SplitMethod::SpatialMedian, "spatial-median"},
         {SplitMethod::CentroidMean, "centroid-mean"},
         {SplitMethod::SampledMean, "sampled-mean"}}};
};
template <>
struct EnumNames<SplitCost> {
    static constexpr std::array<std::pair<SplitCost, std::string_view>, 2> table{
        {{SplitCost::Limits, "limits"}, {SplitCost::RaySampling, "ray-sampling"}}};
};
template <>
struct EnumNames<RayGrouping> {
    static constexpr std::array<std::pair<RayGrouping, std::string_view>, 4> table{{{RayGrouping::Slots, "slots"},
                                                                                    {RayGrouping::Octant, "octant"},
                                                                                    {RayGrouping::OctantCalls, "octant-calls"},
                                                                                    {RayGrouping::Batches, "batches"}}};
};
template <>
struct EnumNames<PassTracing> {
    static constexpr std::array<std::pair<PassTracing, std::string_view>, 3> table{
        {{PassTracing::Auto, "auto"}, {PassTracing::Apart, "apart"}, {PassTracing::Together, "together"}}};
};
template <>
struct EnumNames<DivisionAxis> {
    static constexpr std::array<std::pair<DivisionAxis, std::string_view>, 4> table{
        {{DivisionAxis::Best, "best"}, {DivisionAxis::X, "x"}, {DivisionAxis::Y, "y"}, {DivisionAxis::Z, "z"}}};
};
template <>
struct EnumNames<Intersector> {
    static constexpr std::array<std::pair<Intersector, std::string_view>, 2> table{
        {{Intersector::Watertight, "watertight"}, {Intersector::MollerTrumbore, "moller-trumbore"}}};
};
template <>
struct EnumNames<TriangleFilter> {
    static constexpr std::array<std::pair<TriangleFilter, std::string_view>, 3> table{
        {{TriangleFilter::Bounds, "bounds"}, {TriangleFilter::Sat, "sat"}, {TriangleFilter::Mora, "mora"}}};
};
template <>
struct EnumNames<Precision> {
    static constexpr std::array<std::pair<Precision, std::string_view>, 2> table{
        {{Precision::F32, "f32"}, {Precision::F64, "f64"}}};
};

// Below this many rays, and this many rays x traced triangles, the cpu backend traces the
// frame as one sequential DACRT: the parallel scheme's division and hand-off cost more than a
// second core saves there (measured: docs/skips.md, "The sub-scene crossover").
constexpr std::uint64_t kSequentialBelowRays = 16384;
constexpr std::uint64_t kSequentialBelowPairs = std::uint64_t(1) << 28;

// The skips as --no-skip names them.
template <>
struct EnumNames<Skip> {
    static constexpr std::array<std::pair<Skip, std::string_view>, 5> table{{{Skip::BackFaces, "backfaces"},
                                                                             {Skip::Frustum, "frustum"},
                                                                             {Skip::Uploads, "uploads"},
                                                                             {Skip::SubScenes, "subscenes"},
                                                                             {Skip::PassRays, "passrays"}}};
};

// The peers' builds (public <dacrt/backend_tuning.hpp>), named as the command line and the
// bench's series give them:
template <>
struct EnumNames<EmbreeBuild> {
    static constexpr std::array<std::pair<EmbreeBuild, std::string_view>, 3> table{
        {{EmbreeBuild::Dynamic, "dynamic"}, {EmbreeBuild::Refit, "refit"}, {EmbreeBuild::Static, "static"}}};
};
template <>
struct EnumNames<GpuProfile> {
    static constexpr std::array<std::pair<GpuProfile, std::string_view>, 3> table{
        {{GpuProfile::Auto, "auto"}, {GpuProfile::Cpu, "cpu"}, {GpuProfile::Discrete, "discrete"}}};
};
template <>
struct EnumNames<RayQueryBuild> {
    static constexpr std::array<std::pair<RayQueryBuild, std::string_view>, 3> table{
        {{RayQueryBuild::Dynamic, "dynamic"}, {RayQueryBuild::Refit, "refit"}, {RayQueryBuild::Static, "static"}}};
};

}  // namespace dacrt
