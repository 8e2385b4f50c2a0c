// The table of which backend takes which option (cpu/backend_options.hpp): the refusals it
// derives, at a tracer (the DACRT options alone) and for a whole request.
#include <string>

#include <gtest/gtest.h>

#include "core/errors.hpp"
#include "cpu/backend_options.hpp"

namespace dacrt {
namespace {

// The message of the InputError `check` throws, or "accepted".
template <typename F>
std::string refusal(F&& check) {
    try {
        check();
    } catch (const InputError& e) {
        return e.what();
    }
    return "accepted";
}

TEST(BackendOptions, EveryRowNamesAFlagTakenBySomeBackendButNotAll) {
    for (const BackendOption& row : backendOptions()) {
        EXPECT_EQ(row.flag.substr(0, 2), "--") << row.flag;
        const std::string names = row.takenBy.names();
        EXPECT_FALSE(names.empty()) << row.flag;
        EXPECT_NE(names, "brute, cpu-seq, cpu, gpu, embree, rayquery") << row.flag << " is not backend-specific";
        EXPECT_NE(backendOptionHelp(row).find("(" + names), std::string::npos) << backendOptionHelp(row);
        const TraceOptions defaults;
        EXPECT_FALSE(row.given(RequestedOptions{defaults})) << row.flag << " is given by the defaults";
    }
}

TEST(BackendOptions, ATracerRefusesTheDacrtOptionsItDoesNotTake) {
    TraceOptions gpu;
    gpu.backend = Backend::Gpu;
    gpu.dacrt.split = SplitMethod::CentroidMean;
    gpu.dacrt.splitCost = SplitCost::RaySampling;
    gpu.dacrt.intersector = Intersector::MollerTrumbore;
    gpu.dacrt.packets = false;  // taken by the gpu too
    EXPECT_NE(refusal([&] { checkTraceOptions(gpu); })
                  .find("--split, --split-cost and --intersector are not options of --backend gpu"),
              std::string::npos);
    TraceOptions brute;
    brute.backend = Backend::Brute;
    brute.dacrt.intersector = Intersector::MollerTrumbore;
    EXPECT_NE(refusal([&] { checkTraceOptions(brute); }).find("--intersector is not an option of --backend brute"),
              std::string::npos);
    brute.dacrt = {};
    brute.dacrt.rayLimit = 4;
    EXPECT_NE(refusal([&] { checkTraceOptions(brute); }).find("--ray-limit"), std::string::npos);
}

TEST(BackendOptions, HowATraceRunsIsRefusedForARequestOnly) {
    // A tracer ignores threads and sub-scenes it does not use; a request naming them is refused.
    TraceOptions seq;
    seq.backend = Backend::CpuSeq;
    seq.threads = 2;
    seq.regions = 4;
    EXPECT_EQ(refusal([&] { checkTraceOptions(seq); }), "accepted");
    EXPECT_NE(refusal([&] { checkRequestedOptions({seq}); }).find("--regions and --threads are not options of --backend cpu-seq"),
              std::string::npos);
    TraceOptions cpu;
    cpu.backend = Backend::Cpu;
    EXPECT_NE(refusal([&] { checkRequestedOptions({cpu, 64}); }).find("--workgroup-size is not an option of --backend cpu"),
              std::string::npos);
    EXPECT_NE(refusal([&] { checkRequestedOptions({cpu, 0, 0, true, false}); }).find("--embree-single-rays"),
              std::string::npos);
    cpu.backend = Backend::Embree;
    EXPECT_EQ(refusal([&] { checkRequestedOptions({cpu, 0, 0, false, false}); }), "accepted");
}

TEST(BackendOptions, F64WithMollerTrumboreIsRefusedWhereBothAreTaken) {
    TraceOptions o;
    o.backend = Backend::CpuSeq;
    o.dacrt.precision = Precision::F64;
    EXPECT_EQ(refusal([&] { checkTraceOptions(o); }), "accepted");
    o.dacrt.intersector = Intersector::MollerTrumbore;
    EXPECT_NE(refusal([&] { checkTraceOptions(o); }).find("does not combine with the moller-trumbore intersector"),
              std::string::npos);
    EXPECT_NE(refusal([&] { checkRequestedOptions({o}); }).find("does not combine"), std::string::npos);
}

}  // namespace
}  // namespace dacrt
