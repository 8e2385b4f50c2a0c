#pragma once
// Frame numbers in output names, printf-style: "out_%04d.png" is out_0012.png at frame 12.
// "%d" writes the number as it is, "%0Nd" pads it with zeros to N digits; "%%" is a literal
// percent sign. Every output name is read this way, so a lone '%' is refused with a hint.
#include <cstdint>
#include <string>

namespace dacrt {

// Checks `name` (an output of `option`, "-o") and says whether it holds a frame number: one
// "%d" or "%0Nd" at most, in the file name (not the folder). Throws InputError naming the
// option and the name otherwise.
bool checkFramePattern(const std::string& option, const std::string& name);

// The name with its frame number filled in and "%%" made '%'; a name without a frame number
// only loses its escapes. The name must have passed checkFramePattern.
std::string expandFramePattern(const std::string& name, std::int64_t frame);

// A name made from `name` with a pattern in it, for the message that asks for one:
// "room.png" -> "room_%04d.png".
std::string suggestFramePattern(const std::string& name);

}  // namespace dacrt
