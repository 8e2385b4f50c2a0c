// The kernel's stage clocks (docs/gpu.md, "Where the kernel's time goes"): in the
// DACRT_STAGE_CLOCKS build, each invocation reads its subgroup's clock (VK_KHR_shader_clock)
// around the kernel's stages and sums the ticks per stage (DACRT_STAGE_* in layout.h); the
// first invocation adds its sums to GpuCounters::stageTicks when its launch ends. Without
// DACRT_STAGE_CLOCKS every call below is empty, and the kernel is the one that renders.
// A shader built with DACRT_STAGE_CLOCKS enables GL_ARB_shader_clock at its top.
#ifdef DACRT_STAGE_CLOCKS

// Sums of ticks in 64 bits as (low, high) words, so that no Int64 capability is needed.
uvec2 gStageTicks[DACRT_STAGE_COUNT];

// The clock's low word only: on Mesa 22.3.6's llvmpipe the high word was seen not to follow
// the low word's wraps (a Dragon frame summed to 2^64 - 4e9 ticks), so a stage's ticks are the
// low words' difference, exact for any stage call shorter than 2^32 ticks.
uint stageClock() { return clock2x32ARB().x; }

uvec2 addTicks(uvec2 a, uint b) {
    uint carry;
    uint low = uaddCarry(a.x, b, carry);
    return uvec2(low, a.y + carry);
}

bool fewerTicks(uvec2 a, uvec2 b) { return a.y < b.y || (a.y == b.y && a.x < b.x); }

void addStageTicks(uint stage, uint since) {
    gStageTicks[stage] = addTicks(gStageTicks[stage], stageClock() - since);
}

void clearStageTicks() {
    [[unroll]] for (uint k = 0u; k < DACRT_STAGE_COUNT; ++k) gStageTicks[k] = uvec2(0u);
}

// A launch holds all of its stages, so it lasted at least their sum: that restores the high
// word of a launch longer than 2^32 ticks whose part outside the stages is shorter.
void endLaunchTicks(uint since) {
    uvec2 stages = uvec2(0u);
    [[unroll]] for (uint k = 0u; k < DACRT_STAGE_LAUNCHES; ++k) {
        uint carry;
        stages.x = uaddCarry(stages.x, gStageTicks[k].x, carry);
        stages.y += gStageTicks[k].y + carry;
    }
    uvec2 launch = uvec2(stageClock() - since, stages.y);
    if (fewerTicks(launch, stages)) launch.y += 1u;
    gStageTicks[DACRT_STAGE_LAUNCHES] = launch;
}

// A 64-bit sum from two 32-bit atomics: the carry out of the low word goes to the high one.
// Unrolled, as every loop here, so that no loop limiter (llvmpipe before Mesa 25) counts it.
void publishStageTicks(uint lane) {
    if (lane != 0u) return;
    [[unroll]] for (uint k = 0u; k < DACRT_STAGE_COUNT; ++k) {
        uvec2 t = gStageTicks[k];
        uint before = atomicAdd(counters.stageTicks[2u * k], t.x);
        uint carry = before + t.x < before ? 1u : 0u;
        if (t.y + carry != 0u) atomicAdd(counters.stageTicks[2u * k + 1u], t.y + carry);
    }
}
#else
uint stageClock() { return 0u; }
void addStageTicks(uint stage, uint since) {}
void clearStageTicks() {}
void endLaunchTicks(uint since) {}
void publishStageTicks(uint lane) {}
#endif
