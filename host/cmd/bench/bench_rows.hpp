#pragma once
// What the bench command measures: a configuration (a backend request with a name) and the
// row it yields per scene.
#include <cstddef>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cmd/backend_dispatcher.hpp"
#include "oracle/error_metrics.hpp"

namespace dacrt {

struct BenchConfig {
    std::string series;  // backend, or "embree static"
    std::string name;    // "default" or the option values that differ from it
    BackendRequest request;
    bool isDefault = false;
    Backend backend() const { return request.trace.backend; }
    unsigned threads() const { return BackendDispatcher::threadsOf(request.trace); }
};

struct BenchRow {
    std::string scene;
    std::size_t triangles = 0;
    std::size_t raysPerFrame = 0;
    int cameras = 0;
    BenchConfig config;
    unsigned regions = 0;
    int divisionAxis = -1;
    double frameMsMin = 0.0;
    double frameMsMedian = 0.0;
    std::vector<std::pair<std::string, double>> partsMs;  // mean per frame
    ErrorMetrics errors;
    bool pareto = false;
    std::optional<double> speedupOverSequential;
};

}  // namespace dacrt
