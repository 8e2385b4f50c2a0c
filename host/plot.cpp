#include "plot.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string_view>

#include <OpenImageIO/imageio.h>

#include "errors.hpp"

namespace dacrt {
namespace {

constexpr int kWidth = 1000;
constexpr int kHeight = 700;

struct Rgb {
    std::uint8_t r, g, b;
};

constexpr Rgb kWhite{255, 255, 255};
constexpr Rgb kInk{25, 25, 25};
constexpr Rgb kAxis{70, 70, 70};
constexpr Rgb kMajorGrid{215, 215, 215};
constexpr Rgb kMinorGrid{236, 236, 236};
constexpr Rgb kZeroBandFill{244, 244, 244};
constexpr Rgb kLegendMarker{120, 120, 120};

// Eight hues that stay distinguishable at marker size; documented in plot.hpp, which the tests rely on.
constexpr std::array<Rgb, 8> kPalette{{
    {31, 119, 180},
    {255, 127, 14},
    {44, 160, 44},
    {214, 39, 40},
    {148, 103, 189},
    {140, 86, 75},
    {227, 119, 194},
    {23, 190, 207},
}};

// Printable ASCII in 5x7 cells plus two rows below the baseline for descenders, so that plots
// render identically on machines without fonts. Row bytes run top to bottom; bit 4 is the left
// column.
constexpr int kGlyphColumns = 5;
constexpr int kGlyphRows = 9;
constexpr int kCapHeight = 7;
constexpr int kAdvance = kGlyphColumns + 1;
constexpr char kFirstGlyph = ' ';
constexpr char kLastGlyph = '~';
constexpr std::array<std::array<std::uint8_t, kGlyphRows>, kLastGlyph - kFirstGlyph + 1> kGlyphs{{
    {{0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}},  // space
    {{0x04, 0x04, 0x04, 0x04, 0x04, 0x00, 0x04, 0x00, 0x00}},  // !
    {{0x0A, 0x0A, 0x0A, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}},  // "
    {{0x0A, 0x0A, 0x1F, 0x0A, 0x1F, 0x0A, 0x0A, 0x00, 0x00}},  // #
    {{0x04, 0x0F, 0x14, 0x0E, 0x05, 0x1E, 0x04, 0x00, 0x00}},  // $
    {{0x18, 0x19, 0x02, 0x04, 0x08, 0x13, 0x03, 0x00, 0x00}},  // %
    {{0x0C, 0x12, 0x14, 0x08, 0x15, 0x12, 0x0D, 0x00, 0x00}},  // &
    {{0x04, 0x04, 0x08, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}},  // '
    {{0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02, 0x00, 0x00}},  // (
    {{0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08, 0x00, 0x00}},  // )
    {{0x00, 0x04, 0x15, 0x0E, 0x15, 0x04, 0x00, 0x00, 0x00}},  // *
    {{0x00, 0x04, 0x04, 0x1F, 0x04, 0x04, 0x00, 0x00, 0x00}},  // +
    {{0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x0C, 0x04, 0x08}},  // ,
    {{0x00, 0x00, 0x00, 0x0E, 0x00, 0x00, 0x00, 0x00, 0x00}},  // -
    {{0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x0C, 0x00, 0x00}},  // .
    {{0x00, 0x01, 0x02, 0x04, 0x08, 0x10, 0x00, 0x00, 0x00}},  // /
    {{0x0E, 0x11, 0x11, 0x15, 0x11, 0x11, 0x0E, 0x00, 0x00}},  // 0
    {{0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E, 0x00, 0x00}},  // 1
    {{0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F, 0x00, 0x00}},  // 2
    {{0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E, 0x00, 0x00}},  // 3
    {{0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02, 0x00, 0x00}},  // 4
    {{0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E, 0x00, 0x00}},  // 5
    {{0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E, 0x00, 0x00}},  // 6
    {{0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08, 0x00, 0x00}},  // 7
    {{0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E, 0x00, 0x00}},  // 8
    {{0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C, 0x00, 0x00}},  // 9
    {{0x00, 0x0C, 0x0C, 0x00, 0x0C, 0x0C, 0x00, 0x00, 0x00}},  // :
    {{0x00, 0x0C, 0x0C, 0x00, 0x0C, 0x0C, 0x04, 0x08, 0x00}},  // ;
    {{0x02, 0x04, 0x08, 0x10, 0x08, 0x04, 0x02, 0x00, 0x00}},  // <
    {{0x00, 0x00, 0x1F, 0x00, 0x1F, 0x00, 0x00, 0x00, 0x00}},  // =
    {{0x08, 0x04, 0x02, 0x01, 0x02, 0x04, 0x08, 0x00, 0x00}},  // >
    {{0x0E, 0x11, 0x01, 0x02, 0x04, 0x00, 0x04, 0x00, 0x00}},  // ?
    {{0x0E, 0x11, 0x17, 0x15, 0x17, 0x10, 0x0F, 0x00, 0x00}},  // @
    {{0x0E, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11, 0x00, 0x00}},  // A
    {{0x1E, 0x11, 0x11, 0x1E, 0x11, 0x11, 0x1E, 0x00, 0x00}},  // B
    {{0x0E, 0x11, 0x10, 0x10, 0x10, 0x11, 0x0E, 0x00, 0x00}},  // C
    {{0x1C, 0x12, 0x11, 0x11, 0x11, 0x12, 0x1C, 0x00, 0x00}},  // D
    {{0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x1F, 0x00, 0x00}},  // E
    {{0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x10, 0x00, 0x00}},  // F
    {{0x0E, 0x11, 0x10, 0x17, 0x11, 0x11, 0x0F, 0x00, 0x00}},  // G
    {{0x11, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11, 0x00, 0x00}},  // H
    {{0x0E, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E, 0x00, 0x00}},  // I
    {{0x07, 0x02, 0x02, 0x02, 0x02, 0x12, 0x0C, 0x00, 0x00}},  // J
    {{0x11, 0x12, 0x14, 0x18, 0x14, 0x12, 0x11, 0x00, 0x00}},  // K
    {{0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x1F, 0x00, 0x00}},  // L
    {{0x11, 0x1B, 0x15, 0x15, 0x11, 0x11, 0x11, 0x00, 0x00}},  // M
    {{0x11, 0x11, 0x19, 0x15, 0x13, 0x11, 0x11, 0x00, 0x00}},  // N
    {{0x0E, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E, 0x00, 0x00}},  // O
    {{0x1E, 0x11, 0x11, 0x1E, 0x10, 0x10, 0x10, 0x00, 0x00}},  // P
    {{0x0E, 0x11, 0x11, 0x11, 0x15, 0x12, 0x0D, 0x00, 0x00}},  // Q
    {{0x1E, 0x11, 0x11, 0x1E, 0x14, 0x12, 0x11, 0x00, 0x00}},  // R
    {{0x0F, 0x10, 0x10, 0x0E, 0x01, 0x01, 0x1E, 0x00, 0x00}},  // S
    {{0x1F, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04, 0x00, 0x00}},  // T
    {{0x11, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E, 0x00, 0x00}},  // U
    {{0x11, 0x11, 0x11, 0x11, 0x11, 0x0A, 0x04, 0x00, 0x00}},  // V
    {{0x11, 0x11, 0x11, 0x15, 0x15, 0x15, 0x0A, 0x00, 0x00}},  // W
    {{0x11, 0x11, 0x0A, 0x04, 0x0A, 0x11, 0x11, 0x00, 0x00}},  // X
    {{0x11, 0x11, 0x0A, 0x04, 0x04, 0x04, 0x04, 0x00, 0x00}},  // Y
    {{0x1F, 0x01, 0x02, 0x04, 0x08, 0x10, 0x1F, 0x00, 0x00}},  // Z
    {{0x0E, 0x08, 0x08, 0x08, 0x08, 0x08, 0x0E, 0x00, 0x00}},  // [
    {{0x00, 0x10, 0x08, 0x04, 0x02, 0x01, 0x00, 0x00, 0x00}},  // backslash
    {{0x0E, 0x02, 0x02, 0x02, 0x02, 0x02, 0x0E, 0x00, 0x00}},  // ]
    {{0x04, 0x0A, 0x11, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}},  // ^
    {{0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x1F, 0x00}},  // _
    {{0x08, 0x04, 0x02, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}},  // `
    {{0x00, 0x00, 0x0E, 0x01, 0x0F, 0x11, 0x0F, 0x00, 0x00}},  // a
    {{0x10, 0x10, 0x1E, 0x11, 0x11, 0x11, 0x1E, 0x00, 0x00}},  // b
    {{0x00, 0x00, 0x0E, 0x10, 0x10, 0x11, 0x0E, 0x00, 0x00}},  // c
    {{0x01, 0x01, 0x0F, 0x11, 0x11, 0x11, 0x0F, 0x00, 0x00}},  // d
    {{0x00, 0x00, 0x0E, 0x11, 0x1F, 0x10, 0x0E, 0x00, 0x00}},  // e
    {{0x06, 0x09, 0x08, 0x1C, 0x08, 0x08, 0x08, 0x00, 0x00}},  // f
    {{0x00, 0x00, 0x0F, 0x11, 0x11, 0x11, 0x0F, 0x01, 0x0E}},  // g
    {{0x10, 0x10, 0x16, 0x19, 0x11, 0x11, 0x11, 0x00, 0x00}},  // h
    {{0x04, 0x00, 0x0C, 0x04, 0x04, 0x04, 0x0E, 0x00, 0x00}},  // i
    {{0x02, 0x00, 0x06, 0x02, 0x02, 0x02, 0x02, 0x12, 0x0C}},  // j
    {{0x10, 0x10, 0x12, 0x14, 0x18, 0x14, 0x12, 0x00, 0x00}},  // k
    {{0x0C, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E, 0x00, 0x00}},  // l
    {{0x00, 0x00, 0x1A, 0x15, 0x15, 0x15, 0x15, 0x00, 0x00}},  // m
    {{0x00, 0x00, 0x16, 0x19, 0x11, 0x11, 0x11, 0x00, 0x00}},  // n
    {{0x00, 0x00, 0x0E, 0x11, 0x11, 0x11, 0x0E, 0x00, 0x00}},  // o
    {{0x00, 0x00, 0x1E, 0x11, 0x11, 0x11, 0x1E, 0x10, 0x10}},  // p
    {{0x00, 0x00, 0x0F, 0x11, 0x11, 0x11, 0x0F, 0x01, 0x01}},  // q
    {{0x00, 0x00, 0x16, 0x19, 0x10, 0x10, 0x10, 0x00, 0x00}},  // r
    {{0x00, 0x00, 0x0F, 0x10, 0x0E, 0x01, 0x1E, 0x00, 0x00}},  // s
    {{0x08, 0x08, 0x1C, 0x08, 0x08, 0x09, 0x06, 0x00, 0x00}},  // t
    {{0x00, 0x00, 0x11, 0x11, 0x11, 0x13, 0x0D, 0x00, 0x00}},  // u
    {{0x00, 0x00, 0x11, 0x11, 0x11, 0x0A, 0x04, 0x00, 0x00}},  // v
    {{0x00, 0x00, 0x11, 0x11, 0x15, 0x15, 0x0A, 0x00, 0x00}},  // w
    {{0x00, 0x00, 0x11, 0x0A, 0x04, 0x0A, 0x11, 0x00, 0x00}},  // x
    {{0x00, 0x00, 0x11, 0x11, 0x11, 0x11, 0x0F, 0x01, 0x0E}},  // y
    {{0x00, 0x00, 0x1F, 0x02, 0x04, 0x08, 0x1F, 0x00, 0x00}},  // z
    {{0x03, 0x04, 0x04, 0x08, 0x04, 0x04, 0x03, 0x00, 0x00}},  // {
    {{0x04, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04, 0x00, 0x00}},  // |
    {{0x18, 0x04, 0x04, 0x02, 0x04, 0x04, 0x18, 0x00, 0x00}},  // }
    {{0x00, 0x00, 0x08, 0x15, 0x02, 0x00, 0x00, 0x00, 0x00}},  // ~
}};

const std::array<std::uint8_t, kGlyphRows>& glyph(char c) {
    return c >= kFirstGlyph && c <= kLastGlyph ? kGlyphs[std::size_t(c - kFirstGlyph)] : glyph('?');
}

int textWidth(std::string_view text, int scale) {
    return text.empty() ? 0 : (int(text.size()) * kAdvance - 1) * scale;
}

// Cuts `text` to at most `maxWidth` pixels, marking the cut, so long names cannot push the
// legend or title off the image.
std::string fitText(const std::string& text, int scale, int maxWidth) {
    if (textWidth(text, scale) <= maxWidth) return text;
    const std::string ellipsis = "..";
    std::string cut = text;
    while (!cut.empty() && textWidth(cut + ellipsis, scale) > maxWidth) cut.pop_back();
    return cut + ellipsis;
}

// Pixel edges: pixel (x, y) covers [x, x + 1) x [y, y + 1).
struct Box {
    double left, top, right, bottom;
};

class Canvas {
public:
    Canvas(int width, int height) : width_(width), height_(height), rgb_(std::size_t(width) * std::size_t(height) * 3, 255) {}

    int width() const { return width_; }
    int height() const { return height_; }
    Box bounds() const { return {0.0, 0.0, double(width_), double(height_)}; }
    const std::vector<std::uint8_t>& rgb() const { return rgb_; }

    void fillRect(const Box& area, Rgb colour) {
        paint(area, bounds(), colour, [](double, double) { return 1.0; });
    }

    void disc(double cx, double cy, double radius, Rgb colour, const Box& clip) {
        paint(around(cx, cy, radius), clip, colour,
              [=](double x, double y) { return radius + 0.5 - std::hypot(x - cx, y - cy); });
    }

    void ring(double cx, double cy, double radius, double thickness, Rgb colour, const Box& clip) {
        const double halfThickness = thickness / 2.0;
        paint(around(cx, cy, radius + halfThickness), clip, colour, [=](double x, double y) {
            return halfThickness + 0.5 - std::abs(std::hypot(x - cx, y - cy) - radius);
        });
    }

    void line(double ax, double ay, double bx, double by, double thickness, Rgb colour, const Box& clip) {
        const double halfThickness = thickness / 2.0;
        const Box area{std::min(ax, bx) - halfThickness - 1.0, std::min(ay, by) - halfThickness - 1.0,
                       std::max(ax, bx) + halfThickness + 1.0, std::max(ay, by) + halfThickness + 1.0};
        const double dx = bx - ax, dy = by - ay, lengthSq = dx * dx + dy * dy;
        paint(area, clip, colour, [=](double x, double y) {
            const double t = lengthSq > 0.0 ? std::clamp(((x - ax) * dx + (y - ay) * dy) / lengthSq, 0.0, 1.0) : 0.0;
            return halfThickness + 0.5 - std::hypot(x - (ax + t * dx), y - (ay + t * dy));
        });
    }

    // `left`, `top`: the top-left corner of the first character cell.
    void text(int left, int top, std::string_view text, int scale, Rgb colour) {
        for (std::size_t i = 0; i < text.size(); ++i) {
            const auto& rows = glyph(text[i]);
            const int cellLeft = left + int(i) * kAdvance * scale;
            forEachInk(rows, [&](int column, int row) {
                block(cellLeft + column * scale, top + row * scale, scale, colour);
            });
        }
    }

    // Reads bottom to top, as axis titles beside a vertical axis do.
    void textUpwards(int left, int bottom, std::string_view text, int scale, Rgb colour) {
        for (std::size_t i = 0; i < text.size(); ++i) {
            const auto& rows = glyph(text[i]);
            const int cellBottom = bottom - int(i) * kAdvance * scale;
            forEachInk(rows, [&](int column, int row) {
                block(left + row * scale, cellBottom - (column + 1) * scale, scale, colour);
            });
        }
    }

    // A white outline first keeps small labels readable where they cross grid lines or markers.
    void haloText(int left, int top, std::string_view text, int scale, Rgb colour) {
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx)
                if (dx != 0 || dy != 0) this->text(left + dx, top + dy, text, scale, kWhite);
        this->text(left, top, text, scale, colour);
    }

private:
    static Box around(double cx, double cy, double reach) {
        return {cx - reach - 1.0, cy - reach - 1.0, cx + reach + 1.0, cy + reach + 1.0};
    }

    template <class Visit>
    static void forEachInk(const std::array<std::uint8_t, kGlyphRows>& rows, Visit visit) {
        for (int row = 0; row < kGlyphRows; ++row)
            for (int column = 0; column < kGlyphColumns; ++column)
                if (rows[std::size_t(row)] & (1u << (kGlyphColumns - 1 - column))) visit(column, row);
    }

    void block(int left, int top, int size, Rgb colour) {
        fillRect({double(left), double(top), double(left + size), double(top + size)}, colour);
    }

    // Shapes are coverage fields evaluated at pixel centres: one loop anti-aliases every edge
    // and clips every shape to `clip` (and to the image).
    template <class Coverage>
    void paint(const Box& area, const Box& clip, Rgb colour, Coverage coverage) {
        const Box visible{std::max({area.left, clip.left, 0.0}), std::max({area.top, clip.top, 0.0}),
                          std::min({area.right, clip.right, double(width_)}),
                          std::min({area.bottom, clip.bottom, double(height_)})};
        for (int y = int(std::floor(visible.top)); y < int(std::ceil(visible.bottom)); ++y) {
            const double cy = y + 0.5;
            if (cy < visible.top || cy > visible.bottom) continue;
            for (int x = int(std::floor(visible.left)); x < int(std::ceil(visible.right)); ++x) {
                const double cx = x + 0.5;
                if (cx < visible.left || cx > visible.right) continue;
                blend(x, y, colour, coverage(cx, cy));
            }
        }
    }

    void blend(int x, int y, Rgb colour, double coverage) {
        if (coverage <= 0.0) return;
        const double alpha = std::min(coverage, 1.0);
        std::uint8_t* pixel = &rgb_[(std::size_t(y) * std::size_t(width_) + std::size_t(x)) * 3];
        const std::array<std::uint8_t, 3> source{colour.r, colour.g, colour.b};
        for (std::size_t k = 0; k < 3; ++k)
            pixel[k] = std::uint8_t(std::lround(pixel[k] + (source[k] - pixel[k]) * alpha));
    }

    int width_, height_;
    std::vector<std::uint8_t> rgb_;
};

// Maps log10(value) linearly between two pixel positions.
struct LogAxis {
    double logLow, logHigh;
    double pixelLow, pixelHigh;

    double pixel(double value) const {
        return pixelLow + (std::log10(value) - logLow) / (logHigh - logLow) * (pixelHigh - pixelLow);
    }
    double logAt(double pixel) const {
        return logLow + (pixel - pixelLow) / (pixelHigh - pixelLow) * (logHigh - logLow);
    }
};

// 1, 20, 0.5, 0.002, 5e4: plain decimals up to five characters, exponents beyond.
std::string tickText(int mantissa, int exponent) {
    if (exponent >= 0 && exponent <= 3) return std::to_string(mantissa) + std::string(std::size_t(exponent), '0');
    if (exponent < 0 && exponent >= -3)
        return "0." + std::string(std::size_t(-exponent - 1), '0') + std::to_string(mantissa);
    return std::to_string(mantissa) + "e" + std::to_string(exponent);
}

std::string decadeText(int exponent) { return exponent == 0 ? "1" : "1e" + std::to_string(exponent); }

void validate(const std::vector<PlotPoint>& points) {
    if (points.empty()) throw InputError("cannot plot frame time against error: there are no points");
    for (const PlotPoint& p : points) {
        const std::string who = "plot point '" + p.series + " " + p.label + "'";
        if (!(std::isfinite(p.timeMs) && p.timeMs > 0.0))
            throw InputError(who + ": frame time " + std::to_string(p.timeMs) + " ms is not > 0 (the time axis is logarithmic)");
        if (!(p.error >= 0.0 && p.error <= 1.0))
            throw InputError(who + ": error " + std::to_string(p.error) + " is not a fraction in [0, 1]");
    }
}

std::vector<std::string> seriesInOrderOfAppearance(const std::vector<PlotPoint>& points) {
    std::vector<std::string> names;
    for (const PlotPoint& p : points)
        if (std::find(names.begin(), names.end(), p.series) == names.end()) names.push_back(p.series);
    return names;
}

// Below the smallest non-zero error, so that it sits clear of the axis end; never above 1e-7,
// so that plots of different runs share most of their scale.
double errorFloor(const std::vector<PlotPoint>& points) {
    double smallest = 1.0;
    for (const PlotPoint& p : points)
        if (p.error > 0.0) smallest = std::min(smallest, p.error);
    return std::min(smallest / 3.0, 1e-7);
}

// Scale 2 (12 px per character) for everything read from a distance; point labels are smaller
// because there can be many of them close together.
constexpr int kTextScale = 2;
constexpr int kTitleScale = 3;
constexpr int kPointLabelScale = 1;
constexpr int kTickLength = 6;
constexpr double kMarkerRadius = 5.0;
constexpr double kHighlightRadius = 10.0;
// Keeps markers, with their rings, inside the axes at the ends of both ranges.
constexpr double kAxisInset = 18.0;
constexpr int kLegendRowHeight = 26;
constexpr int kLegendPadding = 12;
constexpr int kLegendIconWidth = 28;
constexpr int kMaxLegendTextWidth = 16 * kAdvance * kTextScale;

struct Layout {
    Box plot;      // both boxes and the gap between them: what data lines are clipped to
    Box errorBox;  // the log error axis
    Box zeroBand;  // error == 0, which a log axis cannot show
    LogAxis time;
    LogAxis error;
    Box legend;
};

struct LegendEntry {
    std::string text;
    Rgb colour;
};

struct MarkerNote {
    std::string text;
    bool filled;
    bool ringed;
};

const std::array<MarkerNote, 3> kMarkerNotes{{
    {"= Pareto front", true, false},
    {"= dominated", false, false},
    {"= default", true, true},
}};

Layout layOut(const std::vector<PlotPoint>& points, double errorAxisFloor, const std::vector<LegendEntry>& series) {
    Layout layout;
    int legendTextWidth = 0;
    for (const LegendEntry& entry : series) legendTextWidth = std::max(legendTextWidth, textWidth(entry.text, kTextScale));
    for (const MarkerNote& note : kMarkerNotes) legendTextWidth = std::max(legendTextWidth, textWidth(note.text, kTextScale));
    const int legendRows = int(series.size() + 1 + kMarkerNotes.size());
    const double legendRight = kWidth - 16.0;
    const double legendLeft = legendRight - (2 * kLegendPadding + kLegendIconWidth + legendTextWidth);

    int widestErrorLabel = textWidth("0", kTextScale);
    for (int exponent = 0; exponent >= int(std::ceil(std::log10(errorAxisFloor))); --exponent)
        widestErrorLabel = std::max(widestErrorLabel, textWidth(decadeText(exponent), kTextScale));

    const double top = 64.0, bottom = kHeight - 72.0;
    const double left = 16.0 + kGlyphRows * kTextScale + 12.0 + widestErrorLabel + kTickLength + 6.0;
    const double right = legendLeft - 24.0;
    const double zeroBandHeight = 40.0, zeroBandGap = 10.0;
    layout.plot = {left, top, right, bottom};
    layout.zeroBand = {left, bottom - zeroBandHeight, right, bottom};
    layout.errorBox = {left, top, right, layout.zeroBand.top - zeroBandGap};
    layout.legend = {legendLeft, top, legendRight, top + 2.0 * kLegendPadding + legendRows * kLegendRowHeight - 8.0};

    double logTimeLow = HUGE_VAL, logTimeHigh = -HUGE_VAL;
    for (const PlotPoint& p : points) {
        logTimeLow = std::min(logTimeLow, std::log10(p.timeMs));
        logTimeHigh = std::max(logTimeHigh, std::log10(p.timeMs));
    }
    // At least a decade, so that at least one decade tick always falls inside the axis.
    const double widen = std::max(0.0, 1.0 - (logTimeHigh - logTimeLow)) / 2.0;
    layout.time = {logTimeLow - widen, logTimeHigh + widen, left + kAxisInset, right - kAxisInset};
    layout.error = {std::log10(errorAxisFloor), 0.0, layout.errorBox.bottom - kAxisInset, top + kAxisInset};
    return layout;
}

double pointY(const Layout& layout, const PlotPoint& p) {
    return p.error > 0.0 ? layout.error.pixel(p.error) : (layout.zeroBand.top + layout.zeroBand.bottom) / 2.0;
}

// A 1 px line centred on a pixel row or column is crisp; centred on a pixel edge it smears over two.
double pixelCentre(double coordinate) { return std::floor(coordinate) + 0.5; }

// Times mantissa x 10^exponent with mantissa 1, 2 or 5, in increasing order, that fall inside the axes.
struct TimeTick {
    double x;
    int mantissa, exponent;
};

std::vector<TimeTick> timeTicks(const Layout& layout) {
    std::vector<TimeTick> ticks;
    const double logLow = layout.time.logAt(layout.plot.left), logHigh = layout.time.logAt(layout.plot.right);
    for (int exponent = int(std::floor(logLow)); exponent <= int(std::ceil(logHigh)); ++exponent)
        for (int mantissa : {1, 2, 5}) {
            const double x = pixelCentre(layout.time.pixel(mantissa * std::pow(10.0, exponent)));
            if (x > layout.plot.left && x < layout.plot.right) ticks.push_back({x, mantissa, exponent});
        }
    return ticks;
}

void drawGrid(Canvas& canvas, const Layout& layout) {
    canvas.fillRect(layout.zeroBand, kZeroBandFill);
    for (const TimeTick& tick : timeTicks(layout))
        for (const Box& box : {layout.errorBox, layout.zeroBand})
            canvas.line(tick.x, box.top, tick.x, box.bottom, 1.0, tick.mantissa == 1 ? kMajorGrid : kMinorGrid, box);
    const double pixelsPerDecade = (layout.error.pixelLow - layout.error.pixelHigh) / -layout.error.logLow;
    for (int exponent = 0; exponent >= int(std::floor(layout.error.logLow)); --exponent)
        for (int mantissa : {1, 2, 5}) {
            // Minor lines only where decades are far enough apart not to turn the grid grey.
            if (mantissa != 1 && pixelsPerDecade < 40.0) continue;
            const double value = mantissa * std::pow(10.0, exponent);
            if (value > 1.0 || std::log10(value) < layout.error.logLow) continue;
            const double y = pixelCentre(layout.error.pixel(value));
            canvas.line(layout.plot.left, y, layout.plot.right, y, 1.0, mantissa == 1 ? kMajorGrid : kMinorGrid,
                        layout.errorBox);
        }
}

void drawParetoFronts(Canvas& canvas, const Layout& layout, const std::vector<PlotPoint>& points,
                      const std::vector<std::string>& series) {
    for (std::size_t s = 0; s < series.size(); ++s) {
        std::vector<const PlotPoint*> front;
        for (const PlotPoint& p : points)
            if (p.pareto && p.series == series[s]) front.push_back(&p);
        std::sort(front.begin(), front.end(), [](const PlotPoint* a, const PlotPoint* b) {
            return a->timeMs != b->timeMs ? a->timeMs < b->timeMs : a->error > b->error;
        });
        const Rgb colour = kPalette[s % kPalette.size()];
        // Right then down: the edge of the region the front dominates (slower and worse).
        for (std::size_t i = 1; i < front.size(); ++i) {
            const double x0 = layout.time.pixel(front[i - 1]->timeMs), y0 = pointY(layout, *front[i - 1]);
            const double x1 = layout.time.pixel(front[i]->timeMs), y1 = pointY(layout, *front[i]);
            canvas.line(x0, y0, x1, y0, 2.0, colour, layout.plot);
            canvas.line(x1, y0, x1, y1, 2.0, colour, layout.plot);
        }
    }
}

void drawMarker(Canvas& canvas, double x, double y, Rgb colour, bool filled, bool ringed, const Box& clip) {
    if (filled) {
        canvas.disc(x, y, kMarkerRadius, colour, clip);
    } else {
        canvas.disc(x, y, kMarkerRadius, kWhite, clip);
        canvas.ring(x, y, kMarkerRadius - 1.0, 2.0, colour, clip);
    }
    if (ringed) canvas.ring(x, y, kHighlightRadius, 1.5, kInk, clip);
}

void drawPoints(Canvas& canvas, const Layout& layout, const std::vector<PlotPoint>& points,
                const std::vector<std::string>& series) {
    // Front points last, so that a dominated point never hides one that matters.
    for (bool pareto : {false, true})
        for (const PlotPoint& p : points) {
            if (p.pareto != pareto) continue;
            const std::size_t s = std::size_t(std::find(series.begin(), series.end(), p.series) - series.begin());
            drawMarker(canvas, layout.time.pixel(p.timeMs), pointY(layout, p), kPalette[s % kPalette.size()],
                       p.pareto, p.highlighted, layout.plot);
        }
    for (const PlotPoint& p : points) {
        if (!p.labelled || p.label.empty()) continue;
        const int x = int(std::lround(layout.time.pixel(p.timeMs)));
        const int y = int(std::lround(pointY(layout, p)));
        const int width = textWidth(p.label, kPointLabelScale), height = kCapHeight * kPointLabelScale;
        // Above and to the right by default: a front's step line leaves a point to the right
        // and reaches it from above, so that corner is free of it.
        const int offset = 8;
        const int left = x + offset + width <= int(layout.plot.right) - 2 ? x + offset : x - offset - width;
        const int top = y - offset - height >= int(layout.plot.top) + 2 ? y - offset - height : y + offset;
        canvas.haloText(left, top, p.label, kPointLabelScale, kInk);
    }
}

void drawFrames(Canvas& canvas, const Layout& layout) {
    for (const Box& box : {layout.errorBox, layout.zeroBand}) {
        const double l = pixelCentre(box.left) - 1.0, r = pixelCentre(box.right), t = pixelCentre(box.top) - 1.0,
                     b = pixelCentre(box.bottom);
        canvas.line(l, t, r, t, 1.0, kAxis, canvas.bounds());
        canvas.line(l, b, r, b, 1.0, kAxis, canvas.bounds());
        canvas.line(l, t, l, b, 1.0, kAxis, canvas.bounds());
        canvas.line(r, t, r, b, 1.0, kAxis, canvas.bounds());
    }
}

void drawTimeAxis(Canvas& canvas, const Layout& layout, const std::string& title) {
    const int tickBase = int(layout.plot.bottom);
    const int tickLabelTop = tickBase + kTickLength + 4;
    struct TickLabel {
        double left, right;
        std::string text;
    };
    auto clearOf = [](const TickLabel& label, const std::vector<TickLabel>& others) {
        const double margin = 8.0;
        return std::none_of(others.begin(), others.end(), [&](const TickLabel& other) {
            return label.right + margin > other.left && label.left - margin < other.right;
        });
    };
    // Decades are placed one at a time; the 2x and 5x labels all together or not at all, since a
    // scale labelled 1, 2, 10, 20, 100 without its fives reads as irregular.
    std::vector<TickLabel> decadeLabels, otherLabels;
    bool otherLabelsFit = true;
    for (const TimeTick& tick : timeTicks(layout)) {
        canvas.line(tick.x, tickBase, tick.x, tickBase + (tick.mantissa == 1 ? kTickLength : kTickLength - 2), 1.0,
                    kAxis, canvas.bounds());
        const std::string text = tickText(tick.mantissa, tick.exponent);
        const double half = textWidth(text, kTextScale) / 2.0;
        const TickLabel label{tick.x - half, tick.x + half, text};
        const bool onImage = label.left >= 0.0 && label.right <= kWidth;
        if (tick.mantissa == 1) {
            if (onImage && clearOf(label, decadeLabels)) decadeLabels.push_back(label);
        } else if (onImage) {
            otherLabelsFit = otherLabelsFit && clearOf(label, otherLabels);
            otherLabels.push_back(label);
        }
    }
    for (const TickLabel& label : otherLabels) otherLabelsFit = otherLabelsFit && clearOf(label, decadeLabels);
    std::vector<TickLabel> placed = decadeLabels;
    if (otherLabelsFit) placed.insert(placed.end(), otherLabels.begin(), otherLabels.end());
    for (const TickLabel& label : placed)
        canvas.text(int(std::lround(label.left)), tickLabelTop, label.text, kTextScale, kInk);

    const std::string fitted = fitText(title, kTextScale, int(layout.plot.right - layout.plot.left));
    canvas.text(int(std::lround((layout.plot.left + layout.plot.right - textWidth(fitted, kTextScale)) / 2.0)),
                tickLabelTop + kCapHeight * kTextScale + 14, fitted, kTextScale, kInk);
}

void drawErrorAxis(Canvas& canvas, const Layout& layout, const std::string& title) {
    const int glyphHeight = kCapHeight * kTextScale;
    const double pixelsPerDecade = (layout.error.pixelLow - layout.error.pixelHigh) / -layout.error.logLow;
    const int labelEvery = std::max(1, int(std::ceil((glyphHeight + 8.0) / pixelsPerDecade)));
    const int tickRight = int(layout.plot.left) - 1;
    auto errorLabel = [&](double y, const std::string& text) {
        canvas.line(tickRight - kTickLength, y, tickRight, y, 1.0, kAxis, canvas.bounds());
        canvas.text(tickRight - kTickLength - 4 - textWidth(text, kTextScale), int(std::lround(y)) - glyphHeight / 2,
                    text, kTextScale, kInk);
    };
    for (int exponent = 0; exponent >= int(std::ceil(layout.error.logLow)); --exponent)
        if (-exponent % labelEvery == 0)
            errorLabel(pixelCentre(layout.error.pixel(std::pow(10.0, exponent))), decadeText(exponent));
    errorLabel(pixelCentre((layout.zeroBand.top + layout.zeroBand.bottom) / 2.0), "0");

    const std::string fitted = fitText(title, kTextScale, int(layout.plot.bottom - layout.plot.top));
    canvas.textUpwards(16, int(std::lround((layout.plot.top + layout.plot.bottom + textWidth(fitted, kTextScale)) / 2.0)),
                       fitted, kTextScale, kInk);
}

void drawTitle(Canvas& canvas, const std::string& title) {
    const int maxWidth = kWidth - 32;
    const int scale = textWidth(title, kTitleScale) <= maxWidth ? kTitleScale : kTextScale;
    const std::string text = fitText(title, scale, maxWidth);
    canvas.text((kWidth - textWidth(text, scale)) / 2, 18, text, scale, kInk);
}

void drawLegend(Canvas& canvas, const Layout& layout, const std::vector<LegendEntry>& series) {
    const Box& box = layout.legend;
    canvas.fillRect(box, kWhite);
    const double l = pixelCentre(box.left), r = pixelCentre(box.right) - 1.0, t = pixelCentre(box.top),
                 b = pixelCentre(box.bottom) - 1.0;
    for (const auto& [ax, ay, bx, by] : {std::array{l, t, r, t}, std::array{l, b, r, b}, std::array{l, t, l, b},
                                         std::array{r, t, r, b}})
        canvas.line(ax, ay, bx, by, 1.0, kAxis, canvas.bounds());

    const int glyphHeight = kCapHeight * kTextScale;
    const double iconX = box.left + kLegendPadding + kLegendIconWidth / 2.0 - 4.0;
    const int textLeft = int(box.left) + kLegendPadding + kLegendIconWidth;
    int rowCentre = int(box.top) + kLegendPadding + kLegendRowHeight / 2 - 4;
    for (const LegendEntry& entry : series) {
        canvas.line(iconX - 10.0, rowCentre, iconX + 10.0, rowCentre, 2.0, entry.colour, box);
        canvas.disc(iconX, rowCentre, kMarkerRadius, entry.colour, box);
        canvas.text(textLeft, rowCentre - glyphHeight / 2, entry.text, kTextScale, kInk);
        rowCentre += kLegendRowHeight;
    }
    rowCentre += kLegendRowHeight;
    for (const MarkerNote& note : kMarkerNotes) {
        drawMarker(canvas, iconX, rowCentre, kLegendMarker, note.filled, note.ringed, box);
        canvas.text(textLeft, rowCentre - glyphHeight / 2, note.text, kTextScale, kInk);
        rowCentre += kLegendRowHeight;
    }
}

void save(const std::string& path, const Canvas& canvas) {
    auto out = OIIO::ImageOutput::create(path);
    if (!out) throw InputError(path + ": cannot write a plot here: " + OIIO::geterror());
    const OIIO::ImageSpec spec(canvas.width(), canvas.height(), 3, OIIO::TypeDesc::UINT8);
    if (!out->open(path, spec) || !out->write_image(OIIO::TypeDesc::UINT8, canvas.rgb().data()) || !out->close())
        throw InputError(path + ": writing the plot failed: " + out->geterror());
}

}  // namespace

void writeTimeErrorPlot(const std::string& path, const std::string& title, const std::string& xLabel,
                        const std::string& yLabel, const std::vector<PlotPoint>& points) {
    validate(points);
    const std::vector<std::string> series = seriesInOrderOfAppearance(points);
    std::vector<LegendEntry> legend;
    for (std::size_t s = 0; s < series.size(); ++s)
        legend.push_back({fitText(series[s], kTextScale, kMaxLegendTextWidth), kPalette[s % kPalette.size()]});

    const Layout layout = layOut(points, errorFloor(points), legend);
    Canvas canvas(kWidth, kHeight);
    drawGrid(canvas, layout);
    drawParetoFronts(canvas, layout, points, series);
    drawPoints(canvas, layout, points, series);
    drawFrames(canvas, layout);
    drawTimeAxis(canvas, layout, xLabel);
    drawErrorAxis(canvas, layout, yLabel);
    drawTitle(canvas, title);
    drawLegend(canvas, layout, legend);
    save(path, canvas);
}

}  // namespace dacrt
