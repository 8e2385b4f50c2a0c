#pragma once
// Benchmark plots: frame time against error, drawn without any font or plotting library so
// that they come out the same on machines with no fonts installed.
#include <string>
#include <vector>

namespace dacrt {

struct PlotPoint {
    std::string series;   // e.g. the backend name; one colour per series, shown in a legend
    std::string label;    // short configuration name, drawn next to the point when `labelled`
    double timeMs = 0.0;  // x: frame time, > 0, drawn on a log10 axis
    double error = 0.0;   // y: an error fraction in [0, 1]; 0 is legal and common
    bool pareto = false;  // on its series' Pareto front: drawn filled and joined by the front's step line
    bool highlighted = false; // the series' default configuration: drawn with a ring around it
    bool labelled = false;
};

// Writes an RGB PNG (any OpenImageIO format by extension) of 1000x700 pixels.
// x: log10 frame time (ms) with decade and 2x/5x ticks labelled; y: error on a log10 axis from a
// floor (the smallest non-zero error / 3, clamped to at most 1e-7) to 1, with every point whose
// error is 0 drawn in a separate band at the bottom labelled "0". Title at the top, axis
// titles xLabel and yLabel. Series take colours in order of first appearance from a fixed
// palette that starts (31,119,180) blue, (255,127,14) orange, (44,160,44) green, and cycles
// after 8. The same input gives the same bytes.
// Throws InputError when there are no points, a point lies outside the axes' domain (time not
// > 0, error not in [0, 1]), or the file cannot be written.
void writeTimeErrorPlot(const std::string& path, const std::string& title, const std::string& xLabel,
                        const std::string& yLabel, const std::vector<PlotPoint>& points);

}  // namespace dacrt
