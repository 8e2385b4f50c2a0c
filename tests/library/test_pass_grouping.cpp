// A secondary pass's rays grouped by octant on the cpu backends (DacrtOptions::rayGrouping):
// through the dispatcher, as every frame's passes go, each grouping gives brute force's
// visibility slot by slot.
#include <gtest/gtest.h>

#include <algorithm>

#include "cpu/options.hpp"
#include "library/backend_dispatcher.hpp"
#include "support/dispatcher_passes.hpp"

namespace dacrt {
namespace {

using namespace test;

// Each pass of the set on brute force, then on cpu-seq and cpu (one region per thread, and
// three) under every grouping, through one dispatcher, as a frame's passes are traced.
void expectEveryGroupingAgrees(const SecondaryPassSet& set) {
    BackendDispatcher dispatcher({}, {Backend::Cpu});
    forEachPassAgainstBruteForce(set, dispatcher, [&](const FrameGeometry& primary, const SecondaryPass& pass,
                                                      const BackendDispatcher::PassTrace& reference) {
        BackendRequest request;
        for (RayGrouping grouping :
             {RayGrouping::Slots, RayGrouping::Octant, RayGrouping::OctantCalls, RayGrouping::Batches})
            for (auto [backend, regions] : {std::pair{Backend::CpuSeq, 0u}, {Backend::Cpu, 0u}, {Backend::Cpu, 3u}}) {
                request.trace.backend = backend;
                request.trace.threads = backend == Backend::CpuSeq ? 0 : 2;
                request.trace.regions = regions;
                request.trace.dacrt.rayGrouping = grouping;
                const BackendDispatcher::PassTrace t = dispatcher.traceSecondary(primary, set.primary.hits, pass, request);
                EXPECT_EQ(t.rays, reference.rays);
                EXPECT_TRUE(identicalVisibility(reference.result.hits, t.result.hits))
                    << toString(backend) << ", " << regions << " regions, grouping " << toString(grouping);
                const bool sorts = grouping == RayGrouping::Octant || grouping == RayGrouping::OctantCalls;
                EXPECT_EQ(t.result.phases.groupRays.has_value(), sorts);
                // cpu's groups side by side, unless regions are asked for: the batches (as many
                // as the workers here) and the octants (these rays take more than one).
                const bool sideBySide = backend == Backend::Cpu && regions == 0 &&
                                        (grouping == RayGrouping::Batches || grouping == RayGrouping::OctantCalls);
                const auto line = std::find_if(t.result.memory.work.begin(), t.result.memory.work.end(),
                                               [](const WorkLine& w) { return w.name == "ray groups side by side"; });
                EXPECT_EQ(line != t.result.memory.work.end(), sideBySide)
                    << toString(backend) << ", " << regions << " regions, grouping " << toString(grouping);
                if (sideBySide && line != t.result.memory.work.end()) {
                    if (grouping == RayGrouping::Batches) {
                        EXPECT_EQ(line->count, 2u);
                    }
                    EXPECT_GE(line->count, 2u);
                    EXPECT_EQ(t.result.threads, 2u);
                }
            }
    });
}

TEST(PassGrouping, EveryGroupingGivesBruteForcesVisibility) {
    expectEveryGroupingAgrees(shapesSecondaryPasses());
    expectEveryGroupingAgrees(shapesUnderACeilingPasses());
}

}  // namespace
}  // namespace dacrt
