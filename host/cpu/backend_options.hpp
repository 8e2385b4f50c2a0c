#pragma once
// Which backend takes which option: one table, from which the command line's help for these
// options (each names its backends; developers' knobs listed apart) and every refusal of an
// option given to a backend that does not take it are derived. The rules that are not about
// one option and one backend (checkOptionCombinations) sit beside it.
#include <cstdint>
#include <initializer_list>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "cpu/options.hpp"

namespace dacrt {

// A set of backends, one bit each.
class BackendSet {
public:
    constexpr BackendSet(std::initializer_list<Backend> backends) {
        for (Backend b : backends) bits_ |= 1u << unsigned(b);
    }
    constexpr bool has(Backend b) const { return (bits_ >> unsigned(b) & 1u) != 0; }
    // The backends' names in Backend's order: "cpu-seq, cpu".
    std::string names() const;

private:
    unsigned bits_ = 0;
};

// What a request asks for, as the table reads it: the trace's options, and the tuning of the
// gpu and embree backends (GpuTuning in gpu/gpu_tracer.hpp, EmbreeOptions in
// peers/embree_tracer.hpp, layers above this one), whose defaults these are. A tracer checks
// its TraceOptions alone: the tuning then keeps these defaults.
struct RequestedOptions {
    const TraceOptions& trace;
    std::uint32_t workgroupSize = 0;
    std::uint32_t rayGroups = 0;
    bool embreeRobust = true;
    bool embreePackets = true;
    GpuProfile gpuProfile = GpuProfile::Auto;
    bool stageClocks = false;
    std::optional<std::uint32_t> leafBalance;
};

// One backend-specific option of `dacrt render`.
struct BackendOption {
    std::string_view flag;  // as the command line names it
    BackendSet takenBy;
    std::string_view help;  // what it does; the help appends the backends, then `note`
    std::string_view note;  // after the backends, in the same parentheses (defaults, exceptions); may be empty
    bool advanced;          // a developer's knob, listed apart in --help
    // A DacrtOptions field: the tracers refuse it themselves too, so that a library caller
    // never gets an image other than the one asked for. The others (threads, sub-scenes,
    // skips, tuning) are refused where a request is checked (checkRequestedOptions).
    bool dacrtOption;
    bool (*given)(const RequestedOptions&);  // whether the request sets it to other than its default
};

// Every backend-specific option of `dacrt render`, in the order a refusal names them.
std::span<const BackendOption> backendOptions();

// "HELP (BACKENDS; NOTE)", the option's line in --help.
std::string backendOptionHelp(const BackendOption& option);

// Throws InputError when f64 is asked of an intersector other than the watertight one: the
// one rule about options together rather than one option and one backend.
void checkOptionCombinations(const DacrtOptions& dacrt);

// Throws InputError naming every option of the table the request gives a backend that does
// not take it (as the command line names them), then checks the combinations.
void checkRequestedOptions(const RequestedOptions& request);

// A tracer's own check: as checkRequestedOptions, for the table's DacrtOptions rows only.
void checkTraceOptions(const TraceOptions& options);

}  // namespace dacrt
