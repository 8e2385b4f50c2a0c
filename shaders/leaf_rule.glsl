// The leaf balance, a leaf rule of the DACRT kernel (kLeafBalance in shaders/dacrt.comp). Valid
// GLSL and, through host/gpu/leaf_rule.hpp, valid C++, so that the host's tests check the very
// function the kernel runs.
#ifndef DACRT_LEAF_RULE_GLSL
#define DACRT_LEAF_RULE_GLSL

// Whether a node of rayCount rays and triCount triangles (both at least 1) costs less as a
// leaf: its leaf makes rayCount x triCount ray/triangle tests, a split partitions its
// rayCount + triCount ids and repeats the question in its children, so the node is a leaf
// where its tests number fewer than `balance` per id a split would partition:
// rays x triangles < balance x (rays + triangles). Written as (rays - balance) x (triangles -
// balance) < balance^2, the same inequality, so that 32-bit integers never overflow: true as
// soon as either count is at most balance, else a product of two positive numbers compared by
// a division. balance 0: never (the leaf limits alone decide); at most 65535.
bool leafUnderBalance(uint rayCount, uint triCount, uint balance) {
    if (balance == 0u) return false;
    if (rayCount <= balance || triCount <= balance) return true;
    uint rayExcess = rayCount - balance;
    uint triExcess = triCount - balance;
    return rayExcess <= (balance * balance - 1u) / triExcess;
}

#endif
