#include "bench/bench_report.hpp"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <optional>
#include <ostream>
#include <sstream>

#include "bench/bench_configs.hpp"
#include "app/json_keys.hpp"
#include "core/atomic_file.hpp"
#include "core/cpu_model.hpp"
#include "core/errors.hpp"
#include "cpu/simd_kernels.hpp"

namespace dacrt {

void markPareto(std::vector<BenchRow>& rows) {
    for (BenchRow& b : rows) {
        b.pareto = true;
        for (const BenchRow& a : rows) {
            if (&a == &b || a.scene != b.scene || a.config.series != b.config.series) continue;
            const double ea = a.errors.realErrorFraction(), eb = b.errors.realErrorFraction();
            const bool clearlyFaster = a.frameMsMin < b.frameMsMin * (1.0 - kParetoTimeMargin);
            if ((ea <= eb && clearlyFaster) || (ea < eb && a.frameMsMin <= b.frameMsMin)) {
                b.pareto = false;
                break;
            }
        }
    }
}

nlohmann::ordered_json runJson(const BenchCommand& cmd, const Tracer& tracer, unsigned hardwareThreads) {
    nlohmann::ordered_json j;
    j["command"] = {{"orbit", cmd.orbit},
                    {"size", std::to_string(cmd.width) + "x" + std::to_string(cmd.height)},
                    {"repeat", cmd.repeat},
                    {"warmup", cmd.warmup},
                    {"suite", toString(cmd.suite)}};
    if (cmd.suite == BenchSuite::Passes) {
        j["command"]["ao"] = cmd.passes.occlusionSamples;
        j["command"]["ao_distance"] = cmd.passes.occlusionDistance;
        j["command"]["light"] = cmd.passes.lights;
    }
    if (cmd.suite == BenchSuite::Animation) {
        j["command"]["frames"] = cmd.animation.frames.text();
        j["command"]["fps"] = cmd.animation.fps;
        j["command"]["animation"] = cmd.animation.animation;
        j["command"].erase("orbit");
    }
    const std::optional<VulkanDeviceProperties> device = tracer.deviceProperties();
    const char* lpThreads = std::getenv("LP_NUM_THREADS");
    j["machine"] = {{"cpu", cpuModelName()},
                    {"simd_target", simd::activeTarget()},
                    {"hardware_threads", hardwareThreads},
                    {"gpu_device", device ? device->name : std::string()},
                    {"gpu_driver", device ? device->driver : std::string()},
                    {"lp_num_threads", lpThreads ? lpThreads : ""}};
    j["validation_errors"] = tracer.validationErrors();
    return j;
}

bool reportValidationErrors(const Tracer& tracer, std::ostream& err) {
    if (!tracer.options().validate || tracer.validationErrors() == 0) return false;
    for (const std::string& m : tracer.validationMessages()) err << "dacrt: validation " << m << "\n";
    err << "dacrt: error: " << tracer.validationErrors() << " Vulkan validation errors\n";
    return true;
}

nlohmann::ordered_json rowJson(const BenchRow& r) {
    const ErrorMetrics& e = r.errors;
    nlohmann::ordered_json j;
    j["scene"] = r.scene;
    j["triangles"] = r.triangles;
    j["rays_per_frame"] = r.raysPerFrame;
    j["cameras"] = r.cameras;
    recordConfig(j, r.config);
    j["regions"] = r.regions;
    j["division_axis"] = r.divisionAxis < 0 ? std::string("-") : std::string(1, "xyz"[r.divisionAxis]);
    j["frame_ms_min"] = r.frameMsMin;
    j["frame_ms_median"] = r.frameMsMedian;
    j["mrays_per_s"] = double(r.raysPerFrame) / (r.frameMsMedian * 1e3);
    j["speedup_over_cpu_seq"] = r.speedupOverSequential ? nlohmann::ordered_json(*r.speedupOverSequential) : nullptr;
    nlohmann::ordered_json parts;
    for (const auto& [name, ms] : r.partsMs) parts[jsonKey(name)] = ms;
    j["parts_ms"] = parts;
    j["pixels"] = e.pixels;
    j["differing_prim"] = e.differingPrim;
    j["near_ties"] = e.nearTies;
    j["real_errors"] = e.realErrors;
    j["real_error_fraction"] = e.realErrorFraction();
    j["near_tie_fraction"] = e.pixels ? double(e.nearTies) / double(e.pixels) : 0.0;
    j["leaks"] = e.leaks;
    j["real_leaks"] = e.realLeaks;
    j["spurious_hits"] = e.spuriousHits;
    j["depth_rel_max"] = e.maxRelDepth;
    j["depth_rel_rms"] = e.rmsRelDepth();
    j["psnr_db"] = std::isinf(e.psnr()) ? nlohmann::ordered_json("inf") : nlohmann::ordered_json(e.psnr());
    j["pareto"] = r.pareto;
    return j;
}

void writeCsvOf(const std::string& path, const std::vector<std::string>& columns,
                const std::vector<nlohmann::ordered_json>& rows) {
    std::ostringstream f;
    for (std::size_t i = 0; i < columns.size(); ++i) f << (i ? "," : "") << columns[i];
    f << "\n";
    for (const nlohmann::ordered_json& j : rows) {
        for (std::size_t i = 0; i < columns.size(); ++i) {
            const nlohmann::ordered_json& v = j.at(columns[i]);
            f << (i ? "," : "");
            if (v.is_string()) {
                std::string text = v.get<std::string>();
                if (text.find_first_of(",\"") != std::string::npos) {
                    std::string quoted = "\"";
                    for (char ch : text) quoted += ch == '"' ? std::string("\"\"") : std::string(1, ch);
                    text = quoted + "\"";
                }
                f << text;
            } else if (v.is_null()) {
                f << "";
            } else {
                f << v.dump();
            }
        }
        f << "\n";
    }
    writeFileAtomically(path, f.str());
}

void writeCsv(const std::string& path, const std::vector<BenchRow>& rows) {
    const std::vector<std::string> columns = {
        "scene", "triangles", "rays_per_frame", "cameras", "backend", "series", "config",
        "default", "options", "threads", "regions", "division_axis", "frame_ms_min",
        "frame_ms_median", "mrays_per_s", "speedup_over_cpu_seq", "pixels", "differing_prim",
        "near_ties", "real_errors", "real_error_fraction", "near_tie_fraction", "leaks",
        "real_leaks", "spurious_hits", "depth_rel_max", "depth_rel_rms", "psnr_db", "pareto"};
    std::vector<nlohmann::ordered_json> json;
    for (const BenchRow& r : rows) json.push_back(rowJson(r));
    writeCsvOf(path, columns, json);
}

void printSummary(const std::vector<BenchRow>& rows) {
    std::cout << std::left << std::setw(18) << "series" << std::setw(34) << "config" << std::right << std::setw(10)
              << "min ms" << std::setw(10) << "median" << std::setw(8) << "Mray/s" << std::setw(9) << "speedup"
              << std::setw(10) << "real err" << std::setw(10) << "near tie" << std::setw(8) << "leaks" << std::setw(9)
              << "PSNR" << "  pareto\n";
    std::string scene;
    for (const BenchRow& r : rows) {
        if (r.scene != scene) {
            scene = r.scene;
            std::cout << "== " << scene << " (" << r.triangles << " triangles, " << r.cameras << " cameras, "
                      << r.raysPerFrame << " rays per frame)\n";
        }
        const double psnr = r.errors.psnr();
        std::ostringstream speed, ps;
        speed << std::fixed << std::setprecision(2);
        if (r.speedupOverSequential) speed << *r.speedupOverSequential << "x";
        ps << std::fixed << std::setprecision(1);
        if (std::isinf(psnr)) ps << "inf"; else ps << psnr;
        std::cout << std::left << std::setw(18) << r.config.series << std::setw(34)
                  << (r.config.name + (r.config.isDefault ? " *" : "")) << std::right << std::fixed
                  << std::setprecision(1) << std::setw(10) << r.frameMsMin << std::setw(10) << r.frameMsMedian
                  << std::setw(8) << double(r.raysPerFrame) / (r.frameMsMedian * 1e3) << std::setw(9) << speed.str()
                  << std::setw(10) << r.errors.realErrors << std::setw(10) << r.errors.nearTies << std::setw(8)
                  << r.errors.leaks << std::setw(9) << ps.str() << "  " << (r.pareto ? "yes" : "no") << "\n";
    }
    std::cout << "(* = the backend's default; errors are pixels summed over the cameras)\n";
}

}  // namespace dacrt
