// sin and cos of several angles at once, for the stage right-hand sides of the Gauss collocation
// members (gauss_collocation.h, cart_birkhoffian.h darboux_rates_stages): the s ≤ 4 steering angles
// of one Newton iteration's stages go through one vector call of SLEEF's deterministic AVX functions
// (Sleef_cinz_sind4_u35avx, Sleef_cinz_cosd4_u35avx: within 3.5 ulp, no FMA) instead of s scalar sin
// and cos calls, which the iteration waits on one after another. tanh of up to four arguments the
// same way (Sleef_cinz_tanhd4_u35avx), for the loads that regularise a sign (the four wheels' rolling
// resistance: effects/rolling_resistance.cpp), in every right-hand side. docs/integrators.md, "Stage
// evaluation".
//
// Two paths, chosen at run time (the build runs on any x86-64), with the same bits:
//  - vector: the AVX call, where the CPU has AVX;
//  - scalar: deterministic::sin, deterministic::cos and deterministic::tanh lane by lane (deterministic_math.h),
//    bit-identical to the members' scalar right-hand side.
// The default is vector where the CPU allows it; the environment variable
// BIRKHOFF_CART_STAGE_EVALUATION=scalar|vector, read once at start, or set_stage_evaluation
// (tests) chooses. Both return SLEEF's bits for every angle, so trajectories are the same on both
// (test/unit/stage_evaluation_test.cpp); the path changes the speed only.
#pragma once

#include <cstdint>
#include <string>

namespace birkhoff_cart {

/// The most angles one call takes [-].
constexpr int kMaxVectorLanes = 4;

enum class StageEvaluation { kScalar, kVector };

/// "scalar" or "vector".
std::string to_string(StageEvaluation evaluation);

/// Does this CPU run the vector path (AVX on x86-64)?
bool vector_stage_evaluation_available();

/// The path in use now.
StageEvaluation stage_evaluation();

/// Chooses the path for the whole process; std::invalid_argument (naming the CPU's lack) when the
/// vector path is asked for where it cannot run. Not thread-safe against running integrations.
void set_stage_evaluation(StageEvaluation evaluation);

/// sines[i] = sin(angles[i]), cosines[i] = cos(angles[i]) for i < count ≤ kMaxVectorLanes [rad → -].
void sin_cos_lanes(const double* angles, int count, double* sines, double* cosines);

/// out[i] = tanh(x[i]) for i < count ≤ kMaxVectorLanes [-], on the same path as sin_cos_lanes and
/// with deterministic::tanh's bits lane by lane.
void tanh_lanes(const double* x, int count, double* out);

/// Calls of sin_cos_lanes in the calling thread so far, on either path (which members evaluate
/// their stages together: integrator_registry_test).
std::uint64_t sin_cos_lanes_calls();

}  // namespace birkhoff_cart
