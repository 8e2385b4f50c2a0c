#pragma once
// How much memory this machine has: the limit every plan is checked against before long work;
// and how the process keeps what it frees.
#include <cstdint>
#include <string>

namespace dacrt {

// Physical memory in bytes, or 0 where the system does not say.
std::uint64_t physicalMemoryBytes();

// Throws InputError when `bytes` exceed the physical memory: "WHAT needs N bytes but this
// machine has M bytes of memory (over by K bytes); ADVICE". Passes where the system does not
// say how much it has.
void checkFitsInMemory(const std::string& what, std::uint64_t bytes, const std::string& advice);

// Keeps freed blocks in the process for the next allocation instead of returning them to the
// system (glibc's mmap threshold and trim threshold raised): a frame's passes and the next
// frame allocate arrays of the same sizes again, and every fresh page costs a fault (on the
// project's VM a secondary pass spent 230-330 ms of its time faulting pages in:
// docs/benchmarks.md). Memory the process has used stays counted against it until it exits.
void reuseFreedMemory();

}  // namespace dacrt
