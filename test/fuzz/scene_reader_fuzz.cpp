// Fuzz target for the scene reader (checks/fuzz_scenes.sh builds and runs it; docs/accuracy.md §3).
//
// One input = the bytes of a scene file. The contract under test: load_scene() either returns a
// Scene or throws SceneError (a one-line message naming the file and the key); an accepted scene
// either makes a Simulation or is refused with std::invalid_argument; that Simulation's first
// steps either succeed with a finite state or throw StepError. Anything else — another exception
// type, a crash, a sanitizer report, a hang (libFuzzer -timeout) — is a finding.
//
// Built two ways:
//  - with clang's libFuzzer (-fsanitize=fuzzer,address,undefined): LLVMFuzzerTestOneInput below;
//  - without it (-DSCENE_FUZZ_MUTATION_LOOP, any compiler): a main() that mutates the seed scenes
//    given on the command line (byte flips, deletions, duplications, numbers swapped for extreme
//    ones) for a fixed number of seconds, deterministic for a given seed.
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <stdexcept>
#include <string>

#include "birkhoff_cart/core/cart_binding/cart_stepper.h"
#include "birkhoff_cart/core/scene/scene.h"
#include "birkhoff_cart/core/run/simulation.h"

namespace {

constexpr int kStepsPerInput = 3;

const std::string& scratch_path() {
  static const std::string path = "/tmp/scene_fuzz_" + std::to_string(getpid()) + ".yaml";
  return path;
}

[[noreturn]] void finding(const std::string& what) {
  std::fprintf(stderr, "scene_reader_fuzz: FINDING: %s\n", what.c_str());
  std::fflush(stderr);
  std::abort();
}

void check_state(const birkhoff_cart::CartState& s) {
  const double values[] = {s.time, s.x, s.y, s.heading, s.steering_angle, s.arc_length, s.forward_speed,
                           s.steering_rate};
  for (double value : values) {
    if (!std::isfinite(value)) finding("a step succeeded with a non-finite state");
  }
}

/// The contract for one scene file's bytes.
void exercise(const std::uint8_t* data, std::size_t size) {
  {
    std::ofstream file(scratch_path(), std::ios::binary | std::ios::trunc);
    file.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  birkhoff_cart::Scene scene;
  try {
    scene = birkhoff_cart::load_scene(scratch_path());
  } catch (const birkhoff_cart::SceneError& error) {
    const std::string message = error.what();
    if (message.find('\n') != std::string::npos) finding("a SceneError message spans lines: " + message);
    return;
  } catch (const std::exception& error) {
    finding(std::string("load_scene threw a non-SceneError: ") + error.what());
  }
  // Keep a run short: a huge duration/step ratio would only cost time.
  try {
    birkhoff_cart::Simulation simulation(scene);
    for (int step = 0; step < kStepsPerInput && simulation.state().time < simulation.end_time(); ++step) {
      simulation.step();
      check_state(simulation.state());
    }
  } catch (const std::invalid_argument&) {
  } catch (const birkhoff_cart::StepError&) {
  } catch (const std::exception& error) {
    finding(std::string("an accepted scene threw ") + error.what());
  }
}

}  // namespace

#ifndef SCENE_FUZZ_MUTATION_LOOP

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  exercise(data, size);
  return 0;
}

#else  // a mutation loop for compilers without libFuzzer

#include <chrono>
#include <random>
#include <sstream>
#include <vector>

namespace {

std::string read_all(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

std::string mutate(std::string text, std::mt19937_64& random) {
  static const char* const kReplacements[] = {"0", "-0", "1e308", "-1e308", "1e-320", ".nan", ".inf", "-.inf",
                                              "", "~", "[]", "{}", "[1, 2]", "\"x\"", "99999999999999999999",
                                              "3.141592653589793", "&a", "*a", "!!binary AA==", "\t", ":", "- "};
  const int mutations = 1 + static_cast<int>(random() % 4);
  for (int m = 0; m < mutations && !text.empty(); ++m) {
    const std::size_t at = random() % text.size();
    switch (random() % 5) {
      case 0: text[at] = static_cast<char>(random() % 256); break;                            // flip a byte
      case 1: text.erase(at, 1 + random() % 16); break;                                       // delete
      case 2: text.insert(at, text.substr(random() % text.size(), 1 + random() % 32)); break;  // duplicate
      case 3: {                                                                               // a value → an extreme
        const std::size_t colon = text.find(": ", at);
        if (colon == std::string::npos) break;
        const std::size_t end = text.find_first_of("#\n", colon + 2);
        text.replace(colon + 2, (end == std::string::npos ? text.size() : end) - colon - 2,
                     kReplacements[random() % (sizeof kReplacements / sizeof *kReplacements)]);
        break;
      }
      default: text.resize(at); break;  // truncate
    }
  }
  return text;
}

}  // namespace

/// scene_reader_fuzz_loop SECONDS SEED SCENE.yaml...
int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: %s SECONDS SEED SCENE.yaml...\n", argv[0]);
    return 2;
  }
  const double budget = std::atof(argv[1]);
  std::mt19937_64 random(std::strtoull(argv[2], nullptr, 10));
  std::vector<std::string> seeds;
  for (int i = 3; i < argc; ++i) seeds.push_back(read_all(argv[i]));
  const auto start = std::chrono::steady_clock::now();
  long executions = 0;
  const std::string last_input = "scene_fuzz_last_input.yaml";  // what to keep when a finding aborts
  while (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() < budget) {
    const std::string input = mutate(seeds[random() % seeds.size()], random);
    std::ofstream(last_input, std::ios::binary | std::ios::trunc) << input;
    exercise(reinterpret_cast<const std::uint8_t*>(input.data()), input.size());
    ++executions;
  }
  std::remove(last_input.c_str());
  std::printf("scene_reader_fuzz: %ld executions in %.0f s, no finding\n", executions, budget);
  return 0;
}

#endif
