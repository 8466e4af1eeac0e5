// work_precision: one measurement per process, for the study runner (scripts/study, docs/studies.md).
//
//   work_precision --measure --scene FILE --duration T --method NAME (--step H | --tolerance TOL)
//                  [--simulator-step S] [--checkpoints t1,t2,...] [--repetitions N] [--label L]
//                  (--reference-file REF.csv | --analytic-reference)
//     one run of one method, timed as the full benchmark times it (measurement.h), against the
//     reference states at the checkpoints; prints ONE JSON object on stdout (the row).
//   work_precision --reference-run --scene FILE --duration T --reference-kind extended_precision|dopri5
//                  [--checkpoints t1,t2,...] [--check-setting] --output REF.csv
//     the reference states at the checkpoints (extended precision: long double rkf78 at 1e-18;
//     dopri5: 1e-13), or with --check-setting those of the run it is checked against (long double
//     bulirsch_stoer at 1e-18; dopri5 at 1e-12: reference.h), written with 17 digits; prints one
//     JSON object naming the run.
// Checkpoints are times from the start [s]; the last one must be the duration (added when missing).
#pragma once

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench_scene.h"
#include "measurement.h"
#include "odeint_peers.h"
#include "ours.h"
#include "output.h"
#include "price.h"
#include "reference.h"

namespace birkhoff_cart {
namespace work_precision {

/// The settings of one task, from the command line.
struct SingleTask {
  std::string mode;             ///< "measure" or "reference-run"
  std::string scene_file, label, method, reference_file, reference_kind, output;
  double duration = NAN;        ///< [s]
  double step = NAN;            ///< fixed step [s]
  double tolerance = NAN;       ///< adaptive methods [-]
  double simulator_step = kSampleInterval;  ///< our dopri5's Simulation step [s]
  std::vector<double> checkpoints;          ///< from the start [s]
  int repetitions = 3;
  bool analytic = false;
  bool check_setting = false;  ///< --reference-run: the second setting the reference is checked against
};

inline double positive_number(const std::string& option, const std::string& text) {
  std::size_t used = 0;
  double value = NAN;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
  }
  if (used != text.size() || !std::isfinite(value) || value <= 0.0) {
    throw std::invalid_argument(option + " needs a finite number > 0, got '" + text + "'");
  }
  return value;
}

inline SingleTask parse_single_task(int argc, char** argv) {
  SingleTask task;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw std::invalid_argument("option " + arg + " needs a value");
      return argv[++i];
    };
    if (arg == "--measure") task.mode = "measure";
    else if (arg == "--reference-run") task.mode = "reference-run";
    else if (arg == "--scene") task.scene_file = value();
    else if (arg == "--label") task.label = value();
    else if (arg == "--method") task.method = value();
    else if (arg == "--duration") task.duration = positive_number(arg, value());
    else if (arg == "--step") task.step = positive_number(arg, value());
    else if (arg == "--tolerance") task.tolerance = positive_number(arg, value());
    else if (arg == "--simulator-step") task.simulator_step = positive_number(arg, value());
    else if (arg == "--reference-file") task.reference_file = value();
    else if (arg == "--analytic-reference") task.analytic = true;
    else if (arg == "--check-setting") task.check_setting = true;
    else if (arg == "--reference-kind") task.reference_kind = value();
    else if (arg == "--output") task.output = value();
    else if (arg == "--repetitions") {
      const double r = positive_number(arg, value());
      if (r != std::floor(r) || r > 1000) throw std::invalid_argument("--repetitions needs a whole number in 1..1000");
      task.repetitions = static_cast<int>(r);
    } else if (arg == "--checkpoints") {
      std::stringstream list(value());
      std::string item;
      while (std::getline(list, item, ',')) task.checkpoints.push_back(positive_number("--checkpoints", item));
    } else {
      throw std::invalid_argument("unknown argument '" + arg + "'");
    }
  }
  if (task.mode.empty()) throw std::invalid_argument("give --measure or --reference-run (one task of a study)");
  if (task.scene_file.empty()) throw std::invalid_argument("--scene FILE is required");
  if (!std::isfinite(task.duration)) throw std::invalid_argument("--duration T is required");
  if (task.checkpoints.empty() || std::abs(task.checkpoints.back() - task.duration) > 1e-12 * task.duration) {
    task.checkpoints.push_back(task.duration);
  }
  for (std::size_t j = 1; j < task.checkpoints.size(); ++j) {
    if (!(task.checkpoints[j] > task.checkpoints[j - 1])) throw std::invalid_argument("--checkpoints must increase");
  }
  if (task.checkpoints.back() > task.duration * (1.0 + 1e-12)) {
    throw std::invalid_argument("--checkpoints must not pass the duration");
  }
  if (task.mode == "measure") {
    if (task.method.empty()) throw std::invalid_argument("--method NAME is required");
    if (std::isnan(task.step) == std::isnan(task.tolerance)) {
      throw std::invalid_argument("give exactly one of --step H (fixed-step methods) and --tolerance TOL");
    }
    if (task.reference_file.empty() != task.analytic) {
      throw std::invalid_argument("give exactly one of --reference-file REF.csv and --analytic-reference");
    }
  } else {
    if (task.reference_kind != "extended_precision" && task.reference_kind != "dopri5") {
      throw std::invalid_argument("--reference-kind must be extended_precision or dopri5, got '" +
                                  task.reference_kind + "'");
    }
    if (task.output.empty()) throw std::invalid_argument("--output REF.csv is required");
  }
  if (task.label.empty()) task.label = task.scene_file;
  return task;
}

/// The settings of `work_precision --price ...` (price.h).
inline PriceSettings parse_price_settings(int argc, char** argv) {
  PriceSettings settings;
  for (int i = 2; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw std::invalid_argument("option " + arg + " needs a value");
      return argv[++i];
    };
    if (arg == "--scene") settings.only_scene = value();
    else if (arg == "--scenes-dir") settings.scenes_dir = value();
    else if (arg == "--tolerance") settings.position_tolerance = positive_number(arg, value());
    else if (arg == "--peer-tolerance") settings.peer_tolerance = positive_number(arg, value());
    else if (arg == "--callgrind") settings.callgrind = true;
    else if (arg == "--repetitions") {
      const double r = positive_number(arg, value());
      if (r != std::floor(r) || r > 1000) throw std::invalid_argument("--repetitions needs a whole number in 1..1000");
      settings.repetitions = static_cast<int>(r);
    } else {
      throw std::invalid_argument("unknown argument '" + arg + "' for --price");
    }
  }
  return settings;
}

inline BenchScene single_task_scene(const SingleTask& task) {
  BenchScene bench;
  bench.scene = load_scene(task.scene_file);
  bench.scene.reference = ReferenceSettings{};
  bench.scene.duration = task.duration;
  bench.label = task.label;
  bench.checkpoint_times = task.checkpoints;
  bench.analytic = task.analytic;
  return bench;
}

/// A JSON number (null for NaN and infinities, which JSON cannot hold).
inline std::string json_number(double value) {
  if (!std::isfinite(value)) return "null";
  char text[40];
  std::snprintf(text, sizeof text, "%.17g", value);
  return text;
}

inline std::string json_string(const std::string& text) {
  std::string out = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    if (static_cast<unsigned char>(c) < 0x20) {
      out += ' ';
      continue;
    }
    out += c;
  }
  return out + "\"";
}

/// The reference file: a header, then t,x,y,heading,heading_low,arc_length per checkpoint.
inline void write_reference_file(const std::string& path, const BenchScene& bench, const ReferenceRun& run) {
  std::FILE* out = open_output(path);
  std::fprintf(out, "# reference %s, scene %s\nt,x,y,heading,heading_low,arc_length\n", run.name.c_str(),
               bench.label.c_str());
  for (std::size_t j = 0; j < bench.checkpoint_times.size(); ++j) {
    const CartState& s = run.states[j];
    std::fprintf(out, "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", bench.checkpoint_times[j], s.x, s.y, s.heading,
                 s.heading_low, s.arc_length);
  }
  if (std::fclose(out) != 0) throw std::runtime_error("cannot write " + path);
}

inline std::vector<CartState> read_reference_file(const std::string& path, const std::vector<double>& times) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read the reference file " + path);
  std::vector<CartState> states;
  std::vector<double> file_times;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#' || line[0] == 't') continue;
    std::stringstream fields(line);
    std::string f;
    std::vector<double> v;
    while (std::getline(fields, f, ',')) v.push_back(std::stod(f));
    if (v.size() != 6) throw std::runtime_error("reference file " + path + ": a row needs 6 fields: " + line);
    CartState s;
    s.x = v[1];
    s.y = v[2];
    s.heading = v[3];
    s.heading_low = v[4];
    s.arc_length = v[5];
    file_times.push_back(v[0]);
    states.push_back(s);
  }
  std::vector<CartState> chosen;
  for (double t : times) {
    std::size_t j = 0;
    while (j < file_times.size() && std::abs(file_times[j] - t) > 1e-9 * t) ++j;
    if (j == file_times.size()) {
      throw std::runtime_error("reference file " + path + " has no state at checkpoint " + json_number(t) + " s");
    }
    chosen.push_back(states[j]);
  }
  return chosen;
}

/// --reference-run: computes and writes the reference (or, with --check-setting, the second
/// setting it is checked against; the study runs both as tasks of their own, in parallel, and
/// compares their files).
inline int run_reference_task(const SingleTask& task) {
  BenchScene bench = single_task_scene(task);
  const ReferenceRun run = reference_run(bench, task.reference_kind, task.check_setting);
  write_reference_file(task.output, bench, run);
  std::printf("{\"reference\":%s,\"setting\":%s,\"rhs_evaluations\":%llu,\"wall_s\":%s}\n",
              json_string(run.name).c_str(), task.check_setting ? "\"check\"" : "\"reference\"",
              static_cast<unsigned long long>(run.rhs_evaluations), json_number(run.wall).c_str());
  return 0;
}

/// --measure: one run, one JSON row on stdout.
inline int run_measure_task(const SingleTask& task) {
  BenchScene bench = single_task_scene(task);
  if (!task.analytic) bench.reference_states = read_reference_file(task.reference_file, bench.checkpoint_times);
  const bool odeint = task.method.compare(0, 7, "odeint_") == 0;
  RunRecord r;
  if (odeint) {
    r = measure_odeint(bench, task.method, task.step, task.tolerance, task.repetitions);
  } else {
    r = measure_ours(bench, task.method, task.step, task.tolerance, task.simulator_step, task.repetitions);
  }
  std::string checkpoints;
  for (const CheckpointError& c : r.errors.checkpoints) {
    if (!checkpoints.empty()) checkpoints += ",";
    checkpoints += "[" + json_number(c.time) + "," + json_number(c.position_error) + "," +
                   json_number(c.max_energy_residual) + "]";
  }
  std::printf(
      "{\"scene\":%s,\"method\":%s,\"kind\":%s,\"duration_s\":%s,\"step_size_s\":%s,\"tolerance\":%s,"
      "\"simulator_step_s\":%s,\"steps\":%llu,\"rhs_evaluations\":%llu,\"passive_evaluations\":%llu,"
      "\"iterations\":%llu,\"repetitions\":%d,\"wall_median_s\":%s,\"cpu_median_s\":%s,\"position_error_m\":%s,"
      "\"heading_error_rad\":%s,\"arc_length_rel_error\":%s,\"max_energy_residual_J\":%s,"
      "\"max_energy_residual_rel\":%s,\"max_p2_residual\":%s,\"status\":%s,\"checkpoints\":[%s]}\n",
      json_string(r.scene).c_str(), json_string(r.method).c_str(), json_string(r.kind).c_str(),
      json_number(r.duration).c_str(), json_number(r.step_size).c_str(), json_number(r.tolerance).c_str(),
      json_number(r.simulator_step).c_str(), static_cast<unsigned long long>(r.steps),
      static_cast<unsigned long long>(r.rhs_evaluations), static_cast<unsigned long long>(r.passive_evaluations),
      static_cast<unsigned long long>(r.iterations), r.repetitions, json_number(r.wall_median).c_str(),
      json_number(r.cpu_median).c_str(), json_number(r.errors.position_error).c_str(),
      json_number(r.errors.heading_error).c_str(), json_number(r.errors.arc_length_rel_error).c_str(),
      json_number(r.errors.max_energy_residual).c_str(),
      json_number(r.errors.max_energy_residual / r.errors.energy_scale).c_str(),
      json_number(r.errors.max_p2_residual).c_str(), json_string(r.status).c_str(), checkpoints.c_str());
  return r.status == "ok" ? 0 : 4;
}

}  // namespace work_precision
}  // namespace birkhoff_cart
