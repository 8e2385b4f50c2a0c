#include "dacrt/memory_plan.hpp"

#include <sstream>

namespace dacrt {

std::string MemoryPlan::describe() const {
    std::ostringstream s;
    for (const auto& [name, bytes] : buffers)
        s << "  " << name << std::string(name.size() < 28 ? 28 - name.size() : 1, ' ') << bytes << " bytes ("
          << std::fixed << double(bytes) / (1024.0 * 1024.0) << " MiB)\n";
    s << "  total" << std::string(23, ' ') << total() << " bytes (" << std::fixed
      << double(total()) / (1024.0 * 1024.0) << " MiB)\n";
    return s.str();
}

}  // namespace dacrt
