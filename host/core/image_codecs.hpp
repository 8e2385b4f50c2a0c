#pragma once
// What dacrt asks of OpenImageIO: encode an image into memory, read a file's or a buffer's
// channels. OpenImageIO and the 255 shared libraries it brings (GDAL, OpenCV, FFmpeg, ...)
// cost every process about half a second of dynamic linking at start, though most commands
// and every test process that fails or traces without an image never use them; so its code
// lives in a module of its own (host/codecs, libdacrt_codecs.so), loaded on the first call of
// imageCodecs(). The module and the caller come from one build of dacrt: the table's
// interface number and layout are checked when it is loaded.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace dacrt {

enum class SampleType : std::uint8_t { UInt8, UInt32, Float, Other };

// One image to encode: its channels, each of a sample type, interleaved pixel by pixel in
// `pixels` (each channel's samples in its own type), and metadata as name/value pairs.
struct ImageToEncode {
    int width = 0;
    int height = 0;
    std::vector<std::string> channelNames;
    std::vector<SampleType> channelTypes;
    int depthChannel = -1;  // the channel that holds depth (OpenEXR's Z), or -1
    std::vector<std::pair<std::string, std::string>> attributes;
    const void* pixels = nullptr;
};

struct ImageHeader {
    int width = 0;
    int height = 0;
    std::vector<std::string> channelNames;
    std::vector<SampleType> channelTypes;  // as stored in the file

    // The first channel of that name, or -1.
    int channelIndex(const std::string& name) const {
        for (std::size_t c = 0; c < channelNames.size(); ++c)
            if (channelNames[c] == name) return int(c);
        return -1;
    }
};

// An open image whose header has been read; its pixels are read channel range by range.
class ImageReader {
public:
    virtual ~ImageReader() = default;
    virtual const ImageHeader& header() const = 0;
    // Channels [first, end) of every pixel, converted to `type`, interleaved into `out` (which
    // holds width x height x (end - first) samples). False, with error() set, on failure.
    virtual bool readChannels(int first, int end, SampleType type, void* out) = 0;
    virtual std::string error() = 0;
};

// Bumped whenever the table or the types above change.
constexpr std::uint32_t kImageCodecsInterface = 1;

// The module's entry points. Each reports failure as text (empty: success) and throws
// nothing: a reader's own exception is caught in the module and becomes the text.
struct ImageCodecs {
    std::uint32_t interface = 0;
    std::uint32_t tableSize = 0;  // sizeof(ImageCodecs) where the module was built
    // Empty when a writer for the path's extension exists and can encode into memory.
    std::string (*writerProblem)(const std::string& path) = nullptr;
    // The file's bytes in the format of the path's extension, or the error.
    std::string (*encode)(const std::string& path, const ImageToEncode& image, std::string& bytes) = nullptr;
    // A file opened by the reader its contents call for.
    std::unique_ptr<ImageReader> (*openFile)(const std::string& path, std::string& error) = nullptr;
    // Bytes in memory, read by the named reader alone ("png", "jpeg", "webp"); colours are
    // kept unassociated from alpha. The bytes must outlive the reader.
    std::unique_ptr<ImageReader> (*openMemory)(const char* reader, std::span<const unsigned char> bytes,
                                               std::string& error) = nullptr;
};

// The symbol the module exports: a function returning its table.
#define DACRT_IMAGE_CODECS_ENTRY "dacrt_image_codecs_table"

// The module's table, loaded on first use (thread-safe). Searched at the path in the
// environment variable DACRT_CODECS_MODULE when set, else beside the build's own module, then
// in the installed library directory. Throws std::runtime_error naming every place tried and
// why each failed when none serves.
const ImageCodecs& imageCodecs();

}  // namespace dacrt
