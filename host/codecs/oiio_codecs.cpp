// The image codecs module (libdacrt_codecs.so): core/image_codecs.hpp's table on OpenImageIO.
// Loaded by dacrt_core on first use; nothing else links OpenImageIO.
#include <exception>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include "core/image_codecs.hpp"

namespace dacrt {
namespace {

OIIO::TypeDesc typeDescOf(SampleType type) {
    switch (type) {
    case SampleType::UInt8: return OIIO::TypeDesc::UINT8;
    case SampleType::UInt32: return OIIO::TypeDesc::UINT32;
    case SampleType::Float: return OIIO::TypeDesc::FLOAT;
    case SampleType::Other: break;
    }
    return OIIO::TypeDesc::UNKNOWN;
}

SampleType sampleTypeOf(OIIO::TypeDesc type) {
    if (type == OIIO::TypeDesc::UINT8) return SampleType::UInt8;
    if (type == OIIO::TypeDesc::UINT32) return SampleType::UInt32;
    if (type == OIIO::TypeDesc::FLOAT) return SampleType::Float;
    return SampleType::Other;
}

// The exception a reader or writer threw, as the text the table reports.
std::string failureText() {
    try {
        throw;
    } catch (const std::exception& e) {
        return std::string("OpenImageIO failed (") + e.what() + ")";
    } catch (...) {
        return "OpenImageIO failed with an unknown exception";
    }
}

std::string writerProblem(const std::string& path) {
    try {
        const auto out = OIIO::ImageOutput::create(path);
        if (!out) {
            const std::string why = OIIO::geterror();
            return why.empty() ? "no image writer for this extension" : why;
        }
        if (!out->supports("ioproxy"))
            return std::string("OpenImageIO's ") + out->format_name() + " writer cannot encode into memory";
        return {};
    } catch (...) {
        return failureText();
    }
}

OIIO::ImageSpec specOf(const ImageToEncode& image) {
    const int channels = int(image.channelNames.size());
    bool uniform = true;
    for (SampleType t : image.channelTypes) uniform = uniform && t == image.channelTypes.front();
    OIIO::ImageSpec spec(image.width, image.height, channels, typeDescOf(image.channelTypes.front()));
    spec.channelnames = image.channelNames;
    if (!uniform)
        for (SampleType t : image.channelTypes) spec.channelformats.push_back(typeDescOf(t));
    spec.z_channel = image.depthChannel;
    for (const auto& [name, value] : image.attributes) spec.attribute(name, value);
    return spec;
}

std::string encode(const std::string& path, const ImageToEncode& image, std::string& bytes) {
    if (image.channelNames.empty() || image.channelNames.size() != image.channelTypes.size())
        return path + ": an image to encode needs one sample type per channel";
    try {
        auto out = OIIO::ImageOutput::create(path);
        if (!out) return path + ": cannot write an image here: " + OIIO::geterror();
        std::vector<unsigned char> memory;
        OIIO::Filesystem::IOVecOutput proxy(memory);
        if (!out->set_ioproxy(&proxy))
            return path + ": OpenImageIO's " + out->format_name() + " writer cannot encode into memory";
        const OIIO::ImageSpec spec = specOf(image);
        // Native per-channel formats when they differ; one type for all of them otherwise.
        const OIIO::TypeDesc format = spec.channelformats.empty() ? spec.format : OIIO::TypeDesc::UNKNOWN;
        if (!out->open(path, spec) || !out->write_image(format, image.pixels) || !out->close())
            return path + ": encoding the image failed: " + out->geterror();
        bytes.assign(memory.begin(), memory.end());
        return {};
    } catch (...) {
        return path + ": " + failureText();
    }
}

class OiioReader final : public ImageReader {
public:
    // `memory` (may be null) is the proxy the reader reads from; it must outlive the reader.
    OiioReader(std::unique_ptr<OIIO::ImageInput> in, std::unique_ptr<OIIO::Filesystem::IOMemReader> memory)
        : memory_(std::move(memory)), in_(std::move(in)) {
        const OIIO::ImageSpec& spec = in_->spec();
        header_.width = spec.width;
        header_.height = spec.height;
        header_.channelNames = spec.channelnames;
        for (int c = 0; c < spec.nchannels; ++c) header_.channelTypes.push_back(sampleTypeOf(spec.channelformat(c)));
    }
    ~OiioReader() override { in_.reset(); }  // before the proxy it reads from

    const ImageHeader& header() const override { return header_; }

    bool readChannels(int first, int end, SampleType type, void* out) override {
        try {
            return in_->read_image(0, 0, first, end, typeDescOf(type), out);
        } catch (...) {
            error_ = failureText();
            return false;
        }
    }

    std::string error() override {
        std::string own = in_->geterror();
        return own.empty() ? error_ : own;
    }

private:
    std::unique_ptr<OIIO::Filesystem::IOMemReader> memory_;
    std::unique_ptr<OIIO::ImageInput> in_;
    ImageHeader header_;
    std::string error_;
};

std::unique_ptr<ImageReader> openFile(const std::string& path, std::string& error) {
    try {
        auto in = OIIO::ImageInput::open(path);
        if (!in) {
            error = OIIO::geterror();
            return nullptr;
        }
        return std::make_unique<OiioReader>(std::move(in), nullptr);
    } catch (...) {
        error = failureText();
        return nullptr;
    }
}

std::unique_ptr<ImageReader> openMemory(const char* reader, std::span<const unsigned char> bytes, std::string& error) {
    try {
        auto memory = std::make_unique<OIIO::Filesystem::IOMemReader>(bytes.data(), bytes.size());
        // glTF colours are not premultiplied by alpha; OpenImageIO's PNG reader would otherwise
        // associate them.
        OIIO::ImageSpec config;
        config.attribute("oiio:UnassociatedAlpha", 1);
        OIIO::Filesystem::IOProxy* proxy = memory.get();  // with a config, the reader takes its proxy from it
        config.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy);
        auto in = OIIO::ImageInput::create(reader, false, &config, memory.get());
        OIIO::ImageSpec opened;
        if (!in || !in->open(std::string("image.") + reader, opened, config)) {
            error = in ? in->geterror() : OIIO::geterror();
            return nullptr;
        }
        return std::make_unique<OiioReader>(std::move(in), std::move(memory));
    } catch (...) {
        error = failureText();
        return nullptr;
    }
}

const ImageCodecs kTable{kImageCodecsInterface, sizeof(ImageCodecs), writerProblem, encode, openFile, openMemory};

}  // namespace
}  // namespace dacrt

extern "C" __attribute__((visibility("default"))) const dacrt::ImageCodecs* dacrt_image_codecs_table() {
    return &dacrt::kTable;
}
