// The two paths of vector_math.h.
#include "birkhoff_cart/core/integrators/vector_math.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

#include "birkhoff_cart/core/integrators/deterministic_math.h"

#if defined(__x86_64__)
#include <immintrin.h>
// SLEEF's deterministic AVX functions, 4 doubles (sleef.h declares them only to translation units
// compiled for AVX): the same bits as deterministic::sin, cos and tanh lane by lane.
extern "C" __m256d Sleef_cinz_sind4_u35avx(__m256d);
extern "C" __m256d Sleef_cinz_cosd4_u35avx(__m256d);
extern "C" __m256d Sleef_cinz_tanhd4_u35avx(__m256d);
#endif

namespace birkhoff_cart {
namespace {

bool cpu_has_vector_path() {
#if defined(__x86_64__)
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx");
#else
  return false;
#endif
}

/// The default: vector where the CPU has it, unless BIRKHOFF_CART_STAGE_EVALUATION says otherwise.
/// An unknown value, or "vector" on a CPU without it, is reported on stderr and the default kept.
StageEvaluation initial_stage_evaluation() {
  const bool available = cpu_has_vector_path();
  const StageEvaluation fallback = available ? StageEvaluation::kVector : StageEvaluation::kScalar;
  const char* chosen = std::getenv("BIRKHOFF_CART_STAGE_EVALUATION");
  if (chosen == nullptr || *chosen == '\0') return fallback;
  const std::string value(chosen);
  if (value == "scalar") return StageEvaluation::kScalar;
  if (value == "vector" && available) return StageEvaluation::kVector;
  std::fprintf(stderr, "birkhoff_cart: BIRKHOFF_CART_STAGE_EVALUATION=%s %s; using %s\n", chosen,
               value == "vector" ? "needs a CPU with AVX" : "is not scalar or vector",
               to_string(fallback).c_str());
  return fallback;
}

/// Per thread, so that counting costs the hot loop no locked instruction.
thread_local std::uint64_t lanes_calls = 0;

StageEvaluation& current_stage_evaluation() {
  static StageEvaluation evaluation = initial_stage_evaluation();
  return evaluation;
}

void sin_cos_scalar(const double* angles, int count, double* sines, double* cosines) {
  for (int i = 0; i < count; ++i) {
    sines[i] = deterministic::sin(angles[i]);
    cosines[i] = deterministic::cos(angles[i]);
  }
}

#if defined(__x86_64__)
__attribute__((target("avx"))) void sin_cos_avx(const double* angles, int count, double* sines,
                                                      double* cosines) {
  alignas(32) double lanes[kMaxVectorLanes] = {0.0, 0.0, 0.0, 0.0};
  for (int i = 0; i < count; ++i) lanes[i] = angles[i];
  const __m256d x = _mm256_load_pd(lanes);
  alignas(32) double sine_lanes[kMaxVectorLanes];
  alignas(32) double cosine_lanes[kMaxVectorLanes];
  _mm256_store_pd(sine_lanes, Sleef_cinz_sind4_u35avx(x));
  _mm256_store_pd(cosine_lanes, Sleef_cinz_cosd4_u35avx(x));
  for (int i = 0; i < count; ++i) {
    sines[i] = sine_lanes[i];
    cosines[i] = cosine_lanes[i];
  }
}

__attribute__((target("avx"))) void tanh_avx(const double* x, int count, double* out) {
  alignas(32) double lanes[kMaxVectorLanes] = {0.0, 0.0, 0.0, 0.0};
  for (int i = 0; i < count; ++i) lanes[i] = x[i];
  alignas(32) double tanh_lanes[kMaxVectorLanes];
  _mm256_store_pd(tanh_lanes, Sleef_cinz_tanhd4_u35avx(_mm256_load_pd(lanes)));
  for (int i = 0; i < count; ++i) out[i] = tanh_lanes[i];
}
#endif

}  // namespace

std::string to_string(StageEvaluation evaluation) {
  return evaluation == StageEvaluation::kVector ? "vector" : "scalar";
}

bool vector_stage_evaluation_available() {
  static const bool available = cpu_has_vector_path();
  return available;
}

StageEvaluation stage_evaluation() { return current_stage_evaluation(); }

void set_stage_evaluation(StageEvaluation evaluation) {
  if (evaluation == StageEvaluation::kVector && !vector_stage_evaluation_available()) {
    throw std::invalid_argument("stage evaluation 'vector' needs a CPU with AVX; this one has not");
  }
  current_stage_evaluation() = evaluation;
}

std::uint64_t sin_cos_lanes_calls() { return lanes_calls; }

void sin_cos_lanes(const double* angles, int count, double* sines, double* cosines) {
  ++lanes_calls;
#if defined(__x86_64__)
  if (current_stage_evaluation() == StageEvaluation::kVector) {
    sin_cos_avx(angles, count, sines, cosines);
    return;
  }
#endif
  sin_cos_scalar(angles, count, sines, cosines);
}

void tanh_lanes(const double* x, int count, double* out) {
#if defined(__x86_64__)
  if (current_stage_evaluation() == StageEvaluation::kVector) {
    tanh_avx(x, count, out);
    return;
  }
#endif
  for (int i = 0; i < count; ++i) out[i] = deterministic::tanh(x[i]);
}

}  // namespace birkhoff_cart
