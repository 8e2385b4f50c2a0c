#include "bench/animation_report.hpp"

#include <algorithm>
#include <functional>
#include <iomanip>
#include <iostream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "bench/bench_configs.hpp"
#include "bench/bench_report.hpp"
#include "app/json_keys.hpp"
#include "core/atomic_file.hpp"

namespace dacrt {
namespace {

using Json = nlohmann::ordered_json;

PhaseStats statsOf(const std::vector<AnimationFrameRow>& rows, const std::function<double(const AnimationFrameRow&)>& value) {
    PhaseStats s;
    if (rows.empty()) return s;
    s.min = s.max = value(rows.front());
    for (const AnimationFrameRow& r : rows) {
        const double v = value(r);
        s.mean += v / double(rows.size());
        s.min = std::min(s.min, v);
        s.max = std::max(s.max, v);
    }
    return s;
}

double mraysOf(std::size_t rays, double ms) { return ms > 0.0 ? double(rays) / (ms * 1e3) : 0.0; }

bool sameConfig(const BenchConfig& a, const BenchConfig& b) { return a.series == b.series && a.name == b.name; }

Json statsJson(const PhaseStats& s) { return Json{{"mean", s.mean}, {"min", s.min}, {"max", s.max}}; }

Json frameRowJson(const AnimationFrameRow& r) {
    Json j;
    j["scene"] = r.scene;
    j["frame"] = r.frame;
    j["time_s"] = r.timeS;
    j["triangles"] = r.triangles;
    j["topology_changed"] = r.topologyChanged;
    recordConfig(j, r.config);
    j["rays_per_frame"] = r.rays;
    j["evaluate_ms"] = r.evaluateMs;
    j["prepare_ms"] = r.prepareMs;
    j["build_ms"] = r.buildMs ? Json(*r.buildMs) : Json(nullptr);
    j["trace_ms"] = r.traceMs;
    j["work_ms"] = r.workMs;
    j["total_ms"] = r.totalMs();
    j["mrays_per_s"] = mraysOf(r.rays, r.workMs);
    j["vertex_copy_ms_not_counted"] = isPeer(r.config.backend()) ? Json(r.copyMs) : Json(nullptr);
    j["rebuilt"] = r.rebuilt;
    Json parts = Json::object();
    for (const auto& [name, ms] : r.partsMs) parts[jsonKey(name)] = ms;
    j["parts_ms"] = parts;
    j["differing"] = r.differing;
    j["near_ties"] = r.nearTies;
    j["real_errors"] = r.realErrors;
    j["exact_required"] = r.exactRequired;
    return j;
}

Json summaryJson(const AnimationSummary& s) {
    Json j;
    j["scene"] = s.scene;
    recordConfig(j, s.config);
    j["frames"] = s.frames;
    j["rays_per_frame"] = s.rays;
    j["triangles"] = statsJson(s.triangles);
    j["evaluate_ms"] = statsJson(s.evaluate);
    j["prepare_ms"] = statsJson(s.prepare);
    j["build_ms"] = s.build ? statsJson(*s.build) : Json(nullptr);
    j["trace_ms"] = statsJson(s.trace);
    j["work_ms"] = statsJson(s.work);
    j["total_ms"] = statsJson(s.total);
    j["mrays_per_s"] = mraysOf(s.rays, s.work.mean);
    j["vertex_copy_ms_not_counted"] = s.copy ? statsJson(*s.copy) : Json(nullptr);
    j["initial_build_ms"] = s.initialBuildMs ? Json(*s.initialBuildMs) : Json(nullptr);
    j["rebuilds"] = s.rebuilds;
    j["differing"] = s.differing;
    j["near_ties"] = s.nearTies;
    j["real_errors"] = s.realErrors;
    j["exact_required"] = s.exactRequired;
    j["cpu_work_ratio"] = s.cpuWorkRatio ? Json(*s.cpuWorkRatio) : Json(nullptr);
    j["cpu_total_ratio"] = s.cpuTotalRatio ? Json(*s.cpuTotalRatio) : Json(nullptr);
    return j;
}

const std::vector<std::string> kCsvColumns = {
    "scene", "row", "frame", "time_s", "triangles", "topology_changed", "backend", "series", "config", "default",
    "options", "threads", "rays_per_frame", "evaluate_ms", "prepare_ms", "build_ms", "trace_ms", "work_ms", "total_ms",
    "mrays_per_s", "vertex_copy_ms_not_counted", "rebuilt", "differing", "near_ties", "real_errors", "exact_required"};

// The summary as three CSV rows (mean, min, max), each phase column holding that statistic
// over the frames.
std::vector<Json> summaryCsvRows(const AnimationSummary& s) {
    std::vector<Json> out;
    for (const char* kind : {"mean", "min", "max"}) {
        auto pick = [&](const PhaseStats& p) { return std::string(kind) == "mean" ? p.mean : std::string(kind) == "min" ? p.min : p.max; };
        Json j;
        j["scene"] = s.scene;
        j["row"] = kind;
        j["frame"] = nullptr;
        j["time_s"] = nullptr;
        j["triangles"] = pick(s.triangles);
        j["topology_changed"] = nullptr;
        recordConfig(j, s.config);
        j["rays_per_frame"] = s.rays;
        j["evaluate_ms"] = pick(s.evaluate);
        j["prepare_ms"] = pick(s.prepare);
        j["build_ms"] = s.build ? Json(pick(*s.build)) : Json(nullptr);
        j["trace_ms"] = pick(s.trace);
        j["work_ms"] = pick(s.work);
        j["total_ms"] = pick(s.total);
        j["mrays_per_s"] = std::string(kind) == "mean" ? mraysOf(s.rays, s.work.mean) : pick(s.mrays);
        j["vertex_copy_ms_not_counted"] = s.copy ? Json(pick(*s.copy)) : Json(nullptr);
        j["rebuilt"] = nullptr;
        j["differing"] = s.differing;
        j["near_ties"] = s.nearTies;
        j["real_errors"] = s.realErrors;
        j["exact_required"] = s.exactRequired;
        out.push_back(std::move(j));
    }
    return out;
}

std::string fixed(double v, int precision = 1) {
    std::ostringstream s;
    s << std::fixed << std::setprecision(precision) << v;
    return s.str();
}

// cpu's time over another's: "1.46x slower" (cpu is), "2.00x faster", as the peers tables say it.
std::string againstText(double cpuOverThis) {
    return cpuOverThis >= 1.0 ? fixed(cpuOverThis, 2) + "x slower" : fixed(1.0 / cpuOverThis, 2) + "x faster";
}

void printFrames(const std::vector<AnimationFrameRow>& rows, const std::vector<BenchConfig>& configs) {
    std::vector<int> widths;
    std::cout << std::right << std::setw(6) << "frame" << std::setw(8) << "time s" << std::setw(11) << "triangles"
              << std::setw(10) << "evaluate";
    for (const BenchConfig& c : configs) {
        widths.push_back(std::max<int>(10, int(configLabel(c).size()) + 2));
        std::cout << std::setw(widths.back()) << configLabel(c);
    }
    std::cout << "\n";
    for (std::size_t i = 0; i < rows.size(); i += configs.size()) {
        const AnimationFrameRow& r = rows[i];
        std::cout << std::setw(6) << r.frame << std::setw(8) << fixed(r.timeS, 3) << std::setw(11)
                  << (std::to_string(r.triangles) + (r.topologyChanged ? "!" : "")) << std::setw(10) << fixed(r.evaluateMs, 2);
        for (std::size_t c = 0; c < configs.size(); ++c) {
            const AnimationFrameRow& x = rows[i + c];
            std::cout << std::setw(widths[c]) << (fixed(x.workMs, 2) + (x.rebuilt ? "r" : ""));
        }
        std::cout << "\n";
    }
}

void printSummary(const std::vector<AnimationSummary>& summaries) {
    std::cout << std::left << std::setw(22) << "series" << std::setw(6) << "" << std::right << std::setw(10) << "evaluate"
              << std::setw(9) << "prepare" << std::setw(9) << "build" << std::setw(9) << "trace" << std::setw(9) << "work"
              << std::setw(9) << "total" << std::setw(8) << "Mray/s" << std::setw(11) << "differing" << std::setw(10)
              << "near tie" << std::setw(6) << "real" << "  cpu against it\n";
    for (const AnimationSummary& s : summaries) {
        for (int k = 0; k < 3; ++k) {
            auto pick = [k](const PhaseStats& p) { return k == 0 ? p.mean : k == 1 ? p.min : p.max; };
            std::cout << std::left << std::setw(22) << (k == 0 ? configLabel(s.config) : "") << std::setw(6)
                      << (k == 0 ? "mean" : k == 1 ? "min" : "max") << std::right << std::setw(10)
                      << fixed(pick(s.evaluate), 2) << std::setw(9) << fixed(pick(s.prepare), 2) << std::setw(9)
                      << (s.build ? fixed(pick(*s.build), 2) : "-") << std::setw(9) << fixed(pick(s.trace), 2)
                      << std::setw(9) << fixed(pick(s.work), 2) << std::setw(9) << fixed(pick(s.total), 2);
            if (k == 0) {
                std::cout << std::setw(8) << fixed(mraysOf(s.rays, s.work.mean), 2) << std::setw(11) << s.differing
                          << std::setw(10) << (s.exactRequired ? "-" : std::to_string(s.nearTies)) << std::setw(6)
                          << (s.exactRequired ? "-" : std::to_string(s.realErrors)) << "  "
                          << (s.cpuWorkRatio && s.config.series != "cpu" ? againstText(*s.cpuWorkRatio) : "-")
                          << (s.exactRequired && s.differing ? "  MUST BE 0" : "");
            }
            std::cout << "\n";
        }
    }
}

}  // namespace

std::vector<AnimationSummary> summarizeAnimation(const std::vector<AnimationFrameRow>& rows) {
    std::vector<AnimationSummary> out;
    std::vector<std::vector<AnimationFrameRow>> groups;
    for (const AnimationFrameRow& r : rows) {
        auto found = std::find_if(out.begin(), out.end(),
                                  [&](const AnimationSummary& s) { return s.scene == r.scene && sameConfig(s.config, r.config); });
        if (found == out.end()) {
            AnimationSummary s;
            s.scene = r.scene;
            s.config = r.config;
            s.rays = r.rays;
            s.exactRequired = r.exactRequired;
            out.push_back(s);
            groups.emplace_back();
            found = out.end() - 1;
        }
        groups[std::size_t(found - out.begin())].push_back(r);
    }
    for (std::size_t g = 0; g < out.size(); ++g) {
        AnimationSummary& s = out[g];
        const std::vector<AnimationFrameRow>& frames = groups[g];
        s.frames = frames.size();
        s.triangles = statsOf(frames, [](const AnimationFrameRow& r) { return double(r.triangles); });
        s.evaluate = statsOf(frames, [](const AnimationFrameRow& r) { return r.evaluateMs; });
        s.prepare = statsOf(frames, [](const AnimationFrameRow& r) { return r.prepareMs; });
        s.trace = statsOf(frames, [](const AnimationFrameRow& r) { return r.traceMs; });
        s.work = statsOf(frames, [](const AnimationFrameRow& r) { return r.workMs; });
        s.total = statsOf(frames, [](const AnimationFrameRow& r) { return r.totalMs(); });
        s.mrays = statsOf(frames, [](const AnimationFrameRow& r) { return mraysOf(r.rays, r.workMs); });
        if (isPeer(s.config.backend())) {
            s.build = statsOf(frames, [](const AnimationFrameRow& r) { return r.buildMs.value_or(0.0); });
            s.copy = statsOf(frames, [](const AnimationFrameRow& r) { return r.copyMs; });
            const bool refit = s.config.backend() == Backend::Embree ? s.config.options.embree.build == EmbreeBuild::Refit
                                                                     : s.config.options.rayQueryBuild == RayQueryBuild::Refit;
            if (refit) s.initialBuildMs = frames.front().initialBuildMs;
        }
        for (const AnimationFrameRow& r : frames) {
            s.differing += r.differing;
            s.nearTies += r.nearTies;
            s.realErrors += r.realErrors;
            s.rebuilds += r.rebuilt;
        }
    }
    for (AnimationSummary& s : out)
        for (const AnimationSummary& cpu : out)
            if (cpu.scene == s.scene && cpu.config.backend() == Backend::Cpu && cpu.config.isDefault) {
                s.cpuWorkRatio = cpu.work.mean / s.work.mean;
                s.cpuTotalRatio = cpu.total.mean / s.total.mean;
            }
    return out;
}

void printAnimationTables(const BenchCommand& cmd, const std::vector<AnimationScene>& scenes,
                          const std::vector<AnimationFrameRow>& rows) {
    const std::vector<AnimationSummary> summaries = summarizeAnimation(rows);
    for (const AnimationScene& scene : scenes) {
        std::vector<AnimationFrameRow> mine;
        for (const AnimationFrameRow& r : rows)
            if (r.scene == scene.name) mine.push_back(r);
        if (mine.empty()) continue;
        std::vector<BenchConfig> configs;
        for (const AnimationFrameRow& r : mine)
            if (std::none_of(configs.begin(), configs.end(), [&](const BenchConfig& c) { return sameConfig(c, r.config); }))
                configs.push_back(r.config);
        std::string animations;
        for (const std::string& a : scene.animations) animations += (animations.empty() ? "" : ", ") + a;
        std::cout << "== " << scene.name << ": "
                  << (scene.animated ? "animations " + animations + (cmd.animation.animation.empty()
                                                                         ? ", all played"
                                                                         : ", playing " + cmd.animation.animation)
                                     : std::string("no animation (every frame the same scene)"))
                  << "; frames " << cmd.animation.frames.text() << " at " << cmd.animation.fps << " fps; " << cmd.width
                  << "x" << cmd.height << " (" << mine.front().rays << " rays per frame); " << cmd.repeat
                  << " timed runs of each frame after " << cmd.warmup << " untimed\n";
        std::cout << "work per frame, ms (the backend's own: prepare + build or refit + trace; the median run):\n";
        printFrames(mine, configs);
        if (!scene.topologyChanges.empty())
            std::cout << "(!: the triangle count differs from the frame before's; r: a refit peer rebuilt its structure "
                         "for it, a refit cannot follow a change of topology)\n";
        std::cout << "summary over the frames, ms per frame (total = evaluate + work; evaluate is the animation "
                     "evaluated into the frame's triangles, the same for every backend):\n";
        std::vector<AnimationSummary> own;
        for (const AnimationSummary& s : summaries)
            if (s.scene == scene.name) own.push_back(s);
        printSummary(own);
    }
    std::cout << "(Mray/s: primary rays per second of work; differing: pixels whose hit differs from cpu-seq's, over "
                 "the frames (dacrt's backends: primitive or depth bits, must be 0; peers: primitive, of which near ties "
                 "and real); cpu against it: cpu's mean work over the row's; peers' vertex copy into their shared array "
                 "is not counted)\n";
}

void writeAnimationOutputs(const BenchCommand& cmd, const std::vector<AnimationScene>& scenes,
                           const std::vector<AnimationFrameRow>& rows, const Tracer& tracer, unsigned hardwareThreads) {
    const std::vector<AnimationSummary> summaries = summarizeAnimation(rows);
    std::vector<Json> csv;
    for (const AnimationFrameRow& r : rows) {
        Json j = frameRowJson(r);
        j["row"] = "frame";
        csv.push_back(std::move(j));
    }
    for (const AnimationSummary& s : summaries)
        for (Json& j : summaryCsvRows(s)) csv.push_back(std::move(j));
    writeCsvOf(cmd.csvPath, kCsvColumns, csv);

    Json j = runJson(cmd, tracer, hardwareThreads);
    j["scenes"] = Json::array();
    for (const AnimationScene& s : scenes)
        j["scenes"].push_back(Json{{"name", s.name},
                                   {"path", s.path},
                                   {"animated", s.animated},
                                   {"animations", s.animations},
                                   {"topology_changes", s.topologyChanges}});
    j["rows"] = Json::array();
    for (const AnimationFrameRow& r : rows) j["rows"].push_back(frameRowJson(r));
    j["summary"] = Json::array();
    for (const AnimationSummary& s : summaries) j["summary"].push_back(summaryJson(s));
    writeFileAtomically(cmd.jsonPath, j.dump(2) + "\n");
}

}  // namespace dacrt
