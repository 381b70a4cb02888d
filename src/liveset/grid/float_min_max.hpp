// std::min and std::max of two floats, with their bits, without a branch (MINSS / MAXSS where there
// is SSE2): GCC compiles std::min of floats to a compare and a jump, which mispredicts wherever the
// winner is not regular (a moving level-set band, the upwind gradient's one-sided differences).
#pragma once

#include <algorithm>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace liveset {

[[gnu::always_inline]] inline float min_of(float a, float b) {
#if defined(__SSE2__)
    return _mm_cvtss_f32(_mm_min_ss(_mm_set_ss(b), _mm_set_ss(a)));  // b < a ? b : a
#else
    return std::min(a, b);
#endif
}

[[gnu::always_inline]] inline float max_of(float a, float b) {
#if defined(__SSE2__)
    return _mm_cvtss_f32(_mm_max_ss(_mm_set_ss(b), _mm_set_ss(a)));  // b > a ? b : a, i.e. a < b ? b : a
#else
    return std::max(a, b);
#endif
}

}  // namespace liveset
