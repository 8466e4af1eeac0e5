// Scene files: every shipped scene loads and says what the scene table (docs/scenes.md) says;
// malformed files are refused with a one-line SceneError naming the file and the key.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "birkhoff_cart/core/physics/effect_library.h"
#include "birkhoff_cart/core/scene/scene.h"
#include "generated_docs.h"
#include "test_scenes.h"

namespace birkhoff_cart {
namespace {

constexpr double kExact = 0.0;  // values read from a file must round-trip exactly [-]

using birkhoff_cart_test::scene_path;

const EffectSpec* find_effect(const Scene& scene, const std::string& name) {
  for (const EffectSpec& spec : scene.effects) {
    if (spec.name == name) return &spec;
  }
  return nullptr;
}

void expect_default_cart(const CartParameters& cart, double wheelbase = 1.05) {
  EXPECT_EQ(cart.wheelbase, wheelbase);
  EXPECT_EQ(cart.rear_half_track, 0.55);
  EXPECT_EQ(cart.front_half_track, 0.5);
  EXPECT_EQ(cart.rear_wheel_radius, 0.14);
  EXPECT_EQ(cart.front_wheel_radius, 0.13);
  EXPECT_EQ(cart.rear_body_mass, 140.0);
  EXPECT_EQ(cart.rear_body_yaw_inertia, 30.0);
  EXPECT_EQ(cart.front_axle_mass, 12.0);
  EXPECT_EQ(cart.front_axle_yaw_inertia, 1.0);
  EXPECT_EQ(cart.rear_wheel_mass, 3.0);
  EXPECT_EQ(cart.rear_wheel_spin_inertia, 0.03);
  EXPECT_EQ(cart.rear_wheel_yaw_inertia, 0.025);
  EXPECT_EQ(cart.front_wheel_mass, 2.2);
  EXPECT_EQ(cart.front_wheel_spin_inertia, 0.019);
  EXPECT_EQ(cart.front_wheel_yaw_inertia, 0.013);
  EXPECT_EQ(cart.gravity, 9.81);
}

/// One row of the scene table: initial (χ, ω1, ω2), duration, enabled effect names.
struct SceneRow {
  std::string name;
  double steering_angle;             // χ [rad]
  double forward_speed;              // ω1 [m/s]
  double steering_rate;              // ω2 [rad/s]
  double duration;                   // [s]
  std::vector<std::string> effects;  // in file order
  std::string integrator = "birkhoff2";  // integrator.name
  double step_size = 1e-3;               // integrator.step_size h [s]
};

class ShippedScene : public ::testing::TestWithParam<SceneRow> {};

TEST_P(ShippedScene, LoadsAndMatchesTheTable) {
  const SceneRow& row = GetParam();
  const Scene scene = load_scene(scene_path(row.name));
  EXPECT_EQ(scene.name, row.name);
  EXPECT_FALSE(scene.description.empty());
  EXPECT_EQ(scene.description.find('\n'), std::string::npos);
  expect_default_cart(scene.cart);
  EXPECT_FALSE(scene.paper_special_case);
  const CartState& state = scene.initial_state;
  EXPECT_EQ(state.time, 0.0);
  EXPECT_EQ(state.x, 0.0);
  EXPECT_EQ(state.y, 0.0);
  EXPECT_EQ(state.heading, 0.0);
  for (double spin : state.wheel_spin_angle) EXPECT_EQ(spin, 0.0);
  EXPECT_EQ(state.arc_length, 0.0);
  EXPECT_NEAR(state.steering_angle, row.steering_angle, kExact);
  EXPECT_NEAR(state.forward_speed, row.forward_speed, kExact);
  EXPECT_NEAR(state.steering_rate, row.steering_rate, kExact);
  EXPECT_NEAR(scene.duration, row.duration, kExact);
  EXPECT_EQ(scene.integrator.name, row.integrator);
  EXPECT_EQ(scene.integrator.step_size, row.step_size);
  EXPECT_EQ(scene.output_rate, 100.0);
  ASSERT_EQ(scene.effects.size(), row.effects.size());
  for (std::size_t i = 0; i < row.effects.size(); ++i) EXPECT_EQ(scene.effects[i].name, row.effects[i]);
  // The effects build against the cart.
  const CartModel model(scene.cart);
  EXPECT_EQ(build_effects(scene.effects, model).size(), row.effects.size());
}

INSTANTIATE_TEST_SUITE_P(
    Scenes, ShippedScene,
    ::testing::Values(
        SceneRow{"free_coast", 0.0, 3.0, 0.5, 6.0, {}},
        SceneRow{"const_steer_torque", 0.0, 4.0, 0.0, 5.0, {"steering_torque"}},
        SceneRow{"sine_steer_torque", 0.0, 5.0, 0.0, 6.0, {"steering_torque"}},
        SceneRow{"drive_rr_drag", 0.0, 0.0, 0.0, 8.0, {"drive_torque", "rolling_resistance", "air_drag", "steering_torque"}},
        SceneRow{"near_jackknife", 1.2, 2.0, 0.41456381575724666, 6.0, {}},
        SceneRow{"jackknife_whirl", 1.2, 2.0, 1.2, 4.0, {}},
        SceneRow{"reverse_jackknife", 0.0, -2.0, -0.05, 6.0, {}},
        SceneRow{"stiff_hinge", 0.3, 3.0, 0.0, 4.0, {"steering_stiffness", "steering_damping"}},
        SceneRow{"default", 0.0, 1.0, 0.0, 60.0,
                 {"drive_torque", "rolling_resistance", "air_drag", "steering_torque", "steering_damping"},
                 "birkhoff_gauss4", 1e-2},
        SceneRow{"noisy_odometry", 0.0, 1.0, 0.0, 60.0,
                 {"drive_torque", "rolling_resistance", "air_drag", "steering_torque", "steering_damping"},
                 "birkhoff_gauss4", 1e-2},
        SceneRow{"steering_actuator", 0.0, 1.0, 0.0, 20.0,
                 {"drive_torque", "rolling_resistance", "air_drag", "steering_torque", "steering_damping"},
                 "birkhoff_gauss4", 1e-2}),
    [](const ::testing::TestParamInfo<SceneRow>& info) { return info.param.name; });

TEST(ShippedScenes, EffectParametersMatchTheTable) {
  const Scene constant = load_scene(scene_path("const_steer_torque"));
  EXPECT_EQ(constant.effects[0].profile.kind, TorqueProfile::Kind::kConstant);
  EXPECT_EQ(constant.effects[0].profile.value, 0.4);

  const Scene sine = load_scene(scene_path("sine_steer_torque"));
  EXPECT_EQ(sine.effects[0].profile.kind, TorqueProfile::Kind::kCosine);
  EXPECT_EQ(sine.effects[0].profile.amplitude, 3.0);
  EXPECT_EQ(sine.effects[0].profile.frequency, 0.5);
  EXPECT_EQ(sine.effects[0].profile.phase, 0.0);

  const Scene drive = load_scene(scene_path("drive_rr_drag"));
  const EffectSpec* torque = find_effect(drive, "drive_torque");
  ASSERT_NE(torque, nullptr);
  EXPECT_EQ(torque->profile.kind, TorqueProfile::Kind::kSmoothSwitchOff);
  EXPECT_EQ(torque->profile.initial, 60.0);
  EXPECT_EQ(torque->profile.switch_off_time, 4.0);
  EXPECT_EQ(torque->profile.width, 0.3);
  EXPECT_EQ(find_effect(drive, "rolling_resistance")->coefficients.at("coefficient"), 0.015);
  EXPECT_EQ(find_effect(drive, "rolling_resistance")->coefficients.at("speed_epsilon"), 0.05);
  EXPECT_EQ(find_effect(drive, "air_drag")->coefficients.at("coefficient"), 0.3);
  const TorqueProfile& steer = find_effect(drive, "steering_torque")->profile;
  for (double time : {0.3, 1.0, 2.7}) {  // 1.5 sin(2π·0.25 t)
    EXPECT_NEAR(steer.at(time), 1.5 * std::sin(2 * M_PI * 0.25 * time), 1e-14);
  }

  const Scene stiff = load_scene(scene_path("stiff_hinge"));
  EXPECT_EQ(find_effect(stiff, "steering_stiffness")->coefficients.at("coefficient"), 2000.0);
  EXPECT_EQ(find_effect(stiff, "steering_damping")->coefficients.at("coefficient"), 5.0);

  const Scene slalom = load_scene(scene_path("default"));
  EXPECT_EQ(slalom.reference.kind, ReferenceSettings::Kind::kShadowRun);
  EXPECT_EQ(slalom.reference.shadow.name, "dopri5");
  EXPECT_EQ(slalom.reference.shadow.tolerance, 1e-12);
  EXPECT_EQ(load_scene(scene_path("free_coast")).reference.kind, ReferenceSettings::Kind::kNone);
  EXPECT_FALSE(slalom.odometry_sensor.has_value());  // odom is the exact state unless a scene says otherwise
  EXPECT_FALSE(slalom.actuators.any());              // commands reach the cart unchanged unless a scene says otherwise

  const Scene motors = load_scene(scene_path("steering_actuator"));  // docs/scenes.md's row
  ASSERT_TRUE(motors.actuators.steering && motors.actuators.drive && motors.actuators.end_stops);
  EXPECT_EQ(motors.actuators.steering->time_constant, 0.1);
  EXPECT_EQ(motors.actuators.steering->dead_time, 0.025);
  EXPECT_EQ(motors.actuators.steering->rate_limit, 10.0);
  EXPECT_EQ(motors.actuators.steering->torque_limit, 2.0);
  EXPECT_EQ(motors.actuators.steering->dead_band, 0.05);
  EXPECT_EQ(motors.actuators.drive->time_constant, 0.5);
  EXPECT_EQ(motors.actuators.drive->torque_limit, 4.0);
  EXPECT_EQ(motors.actuators.drive->dead_time, 0.0);
  EXPECT_EQ(motors.actuators.end_stops->angle, 0.6);
  EXPECT_EQ(motors.actuators.end_stops->restitution, 0.0);
  EXPECT_EQ(find_effect(motors, "steering_torque")->profile.kind, TorqueProfile::Kind::kStep);
  EXPECT_EQ(find_effect(motors, "steering_torque")->profile.final, 3.0);
  EXPECT_EQ(find_effect(motors, "drive_torque")->profile.final, 6.0);

  const Scene noisy = load_scene(scene_path("noisy_odometry"));  // the table's sensor settings
  ASSERT_TRUE(noisy.odometry_sensor.has_value());
  EXPECT_EQ(noisy.odometry_sensor->heading_source, HeadingSource::kGyro);
  EXPECT_EQ(noisy.odometry_sensor->wheel_encoder_counts, 2048u);
  EXPECT_EQ(noisy.odometry_sensor->wheel_distance_noise, 0.002);
  EXPECT_EQ(noisy.odometry_sensor->gyro_noise_density, 5.0e-4);
  EXPECT_EQ(noisy.odometry_sensor->seed, 7u);
}

TEST(ShippedScenes, EveryFileInTheSceneDirectoryLoads) {
  const std::filesystem::path directory = std::string(BIRKHOFF_CART_SOURCE_DIR) + "/config/scenes";
  int loaded = 0;
  for (const auto& entry : std::filesystem::directory_iterator(directory)) {
    if (entry.path().extension() != ".yaml") continue;
    EXPECT_NO_THROW(load_scene(entry.path().string())) << entry.path();
    ++loaded;
  }
  EXPECT_GE(loaded, 10);  // the ten scenes of docs/scenes.md, and any added since
}

TEST(ShippedScenes, PaperSpecialCase) {
  const Scene paper = load_scene(scene_path("paper_special"));
  EXPECT_TRUE(paper.paper_special_case);
  expect_default_cart(paper.cart, 1.0);
  EXPECT_EQ(paper.initial_state.time, M_PI / 2);
  EXPECT_EQ(paper.initial_state.steering_angle, M_PI / 2);
  EXPECT_EQ(paper.initial_state.arc_length, 1.0);
  EXPECT_EQ(paper.initial_state.forward_speed, 1.0);
  EXPECT_EQ(paper.initial_state.steering_rate, 1.0);
  EXPECT_NEAR(paper.initial_state.time + paper.duration, 3.0, 1e-15);
  EXPECT_TRUE(paper.effects.empty());
  EXPECT_EQ(paper.reference.kind, ReferenceSettings::Kind::kPaperAnalytic);
  EXPECT_EQ(paper.integrator.name, "birkhoff2");
  EXPECT_EQ(paper.integrator.step_size, 1e-3);
  EXPECT_EQ(paper.integrator.birkhoffian_form, BirkhoffianForm::kPaper);
}

// ----------------------------------------------------------------------------------------------
// Scenes written by the tests into a private temporary directory.

/// A minimal valid scene: every required key, no optional one.
const std::string kMinimalScene = birkhoff_cart_test::minimal_scene("minimal test scene", "5.0");

class SceneFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    char pattern[] = "/tmp/scene_test_XXXXXX";
    ASSERT_NE(mkdtemp(pattern), nullptr);
    directory_ = pattern;
  }
  void TearDown() override {
    for (const std::string& path : written_) std::remove(path.c_str());
    rmdir(directory_.c_str());
  }
  std::string write(const std::string& name, const std::string& text) {
    const std::string path = directory_ + "/" + name + ".yaml";
    std::ofstream(path) << text;
    written_.push_back(path);
    return path;
  }
  /// kMinimalScene with `from` replaced by `to` (which must occur).
  static std::string edited(const std::string& from, const std::string& to) {
    return birkhoff_cart_test::replaced_once(kMinimalScene, from, to);
  }

  std::string directory_;
  std::vector<std::string> written_;
};

TEST_F(SceneFiles, MinimalSceneGetsTheDocumentedDefaults) {
  const Scene scene = load_scene(write("minimal", kMinimalScene));
  EXPECT_EQ(scene.name, "minimal");
  EXPECT_EQ(scene.description, "minimal test scene");
  EXPECT_FALSE(scene.paper_special_case);
  EXPECT_EQ(scene.initial_state.time, 0.0);
  EXPECT_EQ(scene.initial_state.x, 0.0);
  EXPECT_EQ(scene.initial_state.heading, 0.0);
  EXPECT_EQ(scene.initial_state.arc_length, 0.0);
  EXPECT_EQ(scene.initial_state.steering_angle, 0.1);
  EXPECT_EQ(scene.integrator.name, "rk4");
  EXPECT_EQ(scene.integrator.tolerance, 1e-10);
  EXPECT_EQ(scene.integrator.birkhoffian_form, BirkhoffianForm::kAutonomous);
  EXPECT_EQ(scene.integrator.max_newton_iterations, 30);
  EXPECT_EQ(scene.integrator.newton_tolerance, 1e-14);
  EXPECT_TRUE(scene.integrator.compensated_summation);
  EXPECT_TRUE(scene.integrator.local_error_estimate);
  EXPECT_EQ(scene.output_rate, 100.0);
  EXPECT_TRUE(scene.effects.empty());
  EXPECT_EQ(scene.reference.kind, ReferenceSettings::Kind::kNone);
}

TEST_F(SceneFiles, DisabledEffectIsLeftOutOfTheScene) {
  const Scene scene = load_scene(write("disabled", std::string(kMinimalScene) + R"(effects:
  air_drag: {coefficient: 0.3, enabled: false}
  steering_damping: {coefficient: 2.0}
  steering_torque: {profile: step, initial: 1.0, final: 0.0, step_time: 2.0, enabled: false}
)"));
  ASSERT_EQ(scene.effects.size(), 1u);
  EXPECT_EQ(scene.effects[0].name, "steering_damping");
}

TEST_F(SceneFiles, CommandAndRampProfilesAndShadowReference) {
  const Scene scene = load_scene(write("profiles", std::string(kMinimalScene) + R"(effects:
  steering_torque: {profile: command, value: 0.25}
  drive_torque: {profile: ramp, initial: 0.0, final: 10.0, start_time: 1.0, end_time: 3.0}
reference:
  kind: shadow_run
  integrator: {name: dopri5, step_size: 0.001, tolerance: 1.0e-12}
)"));
  ASSERT_EQ(scene.effects.size(), 2u);
  EXPECT_EQ(scene.effects[0].profile.kind, TorqueProfile::Kind::kCommand);
  EXPECT_EQ(scene.effects[0].profile.value, 0.25);
  EXPECT_EQ(scene.effects[1].profile.kind, TorqueProfile::Kind::kRamp);
  EXPECT_EQ(scene.effects[1].profile.at(2.0), 5.0);
  EXPECT_EQ(scene.reference.shadow.name, "dopri5");
  EXPECT_EQ(scene.reference.shadow.tolerance, 1e-12);
}

/// One malformed file and the key its error must name.
struct MalformedCase {
  std::string label;
  std::string text;
  std::string key;
};

TEST_F(SceneFiles, MalformedScenesNameTheFileAndTheKey) {
  std::string tiny_cart = kMinimalScene;  // every mass and inertia 1e-200: det M underflows to 0
  for (const char* name : {"rear_body_mass: 140.0", "rear_body_yaw_inertia: 30.0", "front_axle_mass: 12.0",
                           "front_axle_yaw_inertia: 1.0", "rear_wheel_mass: 3.0", "rear_wheel_spin_inertia: 0.03",
                           "rear_wheel_yaw_inertia: 0.025", "front_wheel_mass: 2.2", "front_wheel_spin_inertia: 0.019",
                           "front_wheel_yaw_inertia: 0.013"}) {
    const std::string entry = name;
    tiny_cart.replace(tiny_cart.find(entry), entry.size(), entry.substr(0, entry.find(':')) + ": 1.0e-200");
  }
  const std::string with_effects = std::string(kMinimalScene) + "effects:\n";
  const std::vector<MalformedCase> cases = {
      {"two_line_description", edited("description: minimal test scene\n", "description: |\n  two\n  lines\n"),
       "description"},
      {"missing_key", edited("  wheelbase: 1.05\n", ""), "cart.wheelbase"},
      {"missing_section", edited("duration: 5.0\n", ""), "duration"},
      {"unknown_key", edited("  gravity: 9.81\n", "  gravity: 9.81\n  wheel_base: 1.0\n"), "cart.wheel_base"},
      {"unknown_top_key", std::string(kMinimalScene) + "colour: red\n", "colour"},
      {"wrong_type_number", edited("duration: 5.0", "duration: six"), "duration"},
      {"wrong_type_map", edited("integrator:\n  name: rk4\n  step_size: 0.01\n", "integrator: rk4\n"), "integrator"},
      {"wrong_type_bool", std::string(kMinimalScene) + "paper_special_case: maybe\n", "paper_special_case"},
      {"negative_mass", edited("rear_body_mass: 140.0", "rear_body_mass: -140.0"), "cart.rear_body_mass"},
      {"zero_mass", edited("front_wheel_mass: 2.2", "front_wheel_mass: 0"), "cart.front_wheel_mass"},
      {"zero_wheelbase", edited("wheelbase: 1.05", "wheelbase: 0.0"), "cart.wheelbase"},
      {"nan_value", edited("rear_body_yaw_inertia: 30.0", "rear_body_yaw_inertia: .nan"), "cart.rear_body_yaw_inertia"},
      {"degenerate_mass_matrix", tiny_cart, "cart"},
      {"paper_flag_wheelbase", std::string(kMinimalScene) + "paper_special_case: true\n", "cart.wheelbase"},
      {"unknown_effect", with_effects + "  wind_gust: {coefficient: 1.0}\n", "effects.wind_gust"},
      {"negative_coefficient", with_effects + "  air_drag: {coefficient: -0.3}\n", "effects.air_drag.coefficient"},
      {"zero_speed_epsilon", with_effects + "  rolling_resistance: {coefficient: 0.01, speed_epsilon: 0}\n",
       "effects.rolling_resistance.speed_epsilon"},
      {"missing_profile", with_effects + "  steering_torque: {value: 1.0}\n", "effects.steering_torque.profile"},
      {"unknown_profile", with_effects + "  steering_torque: {profile: square, value: 1.0}\n",
       "effects.steering_torque.profile"},
      {"key_of_other_profile", with_effects + "  steering_torque: {profile: constant, value: 1.0, amplitude: 2.0}\n",
       "effects.steering_torque.amplitude"},
      {"ramp_backwards", with_effects + "  drive_torque: {profile: ramp, initial: 0, final: 1, start_time: 3, end_time: 1}\n",
       "effects.drive_torque.end_time"},
      {"unknown_integrator", edited("name: rk4", "name: euler"), "integrator.name"},
      {"zero_step", edited("step_size: 0.01", "step_size: 0.0"), "integrator.step_size"},
      {"estimate_not_bool", edited("  step_size: 0.01\n", "  step_size: 0.01\n  local_error_estimate: often\n"),
       "integrator.local_error_estimate"},
      {"estimate_as_map", edited("  step_size: 0.01\n", "  step_size: 0.01\n  local_error_estimate: {on: true}\n"),
       "integrator.local_error_estimate"},
      {"negative_step", edited("step_size: 0.01", "step_size: -0.01"), "integrator.step_size"},
      {"step_longer_than_run", edited("step_size: 0.01", "step_size: 10.0"), "integrator.step_size"},
      {"zero_duration", edited("duration: 5.0", "duration: 0"), "duration"},
      {"negative_duration", edited("duration: 5.0", "duration: -5.0"), "duration"},
      {"bad_birkhoffian_form", edited("  step_size: 0.01\n", "  step_size: 0.01\n  birkhoffian_form: hamiltonian\n"),
       "integrator.birkhoffian_form"},
      {"infinite_initial_speed", edited("forward_speed: 2.0", "forward_speed: .inf"), "initial_state.forward_speed"},
      {"nan_wheel_angle", edited("  steering_rate: 0.3\n", "  steering_rate: 0.3\n  wheel_spin_angles: [0, 0, .nan, 0]\n"),
       "initial_state.wheel_spin_angles[2]"},
      {"three_wheel_angles", edited("  steering_rate: 0.3\n", "  steering_rate: 0.3\n  wheel_spin_angles: [0, 0, 0]\n"),
       "initial_state.wheel_spin_angles"},
      {"zero_output_rate", std::string(kMinimalScene) + "output_rate: 0\n", "output_rate"},
      {"analytic_reference_without_paper_flag", std::string(kMinimalScene) + "reference: {kind: paper_analytic}\n",
       "reference.kind"},
      {"shadow_without_integrator", std::string(kMinimalScene) + "reference: {kind: shadow_run}\n",
       "reference.integrator"},
      {"duplicate_key", std::string(kMinimalScene) + "duration: 7.0\n", "duration"},
      {"syntax_error", edited("cart:\n", "cart: [1, 2\n"), "(syntax)"},
      {"empty_file", "", "(document)"},
  };
  ASSERT_GE(cases.size(), 15u);
  // The pages that count these cases state this count.
  EXPECT_TRUE(birkhoff_cart_test::page_states("docs/developing.md", std::to_string(cases.size()) + " malformed scenes, each"));
  EXPECT_TRUE(birkhoff_cart_test::page_states("docs/hard_cases.md", "scene_test.cpp covers " + std::to_string(cases.size()) + " malformed"));
  for (const MalformedCase& malformed : cases) {
    const std::string path = write(malformed.label, malformed.text);
    try {
      load_scene(path);
      ADD_FAILURE() << malformed.label << ": accepted";
    } catch (const SceneError& error) {
      const std::string message = error.what();
      EXPECT_EQ(error.file(), path) << malformed.label;
      EXPECT_EQ(error.key(), malformed.key) << malformed.label << ": " << message;
      EXPECT_EQ(message.rfind("scene " + path + ": key '" + malformed.key + "': ", 0), 0u) << malformed.label << ": " << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << malformed.label;
    }
  }
}

TEST_F(SceneFiles, EveryEffectCoefficientIsCheckedInItsRowsRange) {
  // The reader checks each coefficient of every row of the effect table (effect_library.h) once, in
  // the row's range: the typical value loads; a negative, a non-finite and (kPositive) a zero one are
  // refused naming effects.<effect>.<key>; a torque effect takes no coefficient.
  int checked = 0;
  for (const EffectEntry& row : effect_table()) {
    if (row.takes_profile()) {
      const std::string text = std::string(kMinimalScene) + "effects:\n  " + row.name + ": {profile: constant, value: 1.0, coefficient: 1.0}\n";
      EXPECT_THROW(load_scene(write(std::string(row.name) + "_with_coefficient", text)), SceneError) << row.name;
      continue;
    }
    auto scene_with = [&](const std::string& key, const std::string& value) {
      std::string map;
      for (const EffectCoefficient& coefficient : row.coefficients) {
        std::ostringstream text;
        text.precision(17);
        text << coefficient.typical;
        map += std::string(map.empty() ? "" : ", ") + coefficient.key + ": " + (coefficient.key == key ? value : text.str());
      }
      return std::string(kMinimalScene) + "effects:\n  " + row.name + ": {" + map + "}\n";
    };
    const Scene typical = load_scene(write(std::string(row.name) + "_typical", scene_with("", "")));
    ASSERT_EQ(typical.effects.size(), 1u);
    EXPECT_EQ(typical.effects[0].coefficients.size(), row.coefficients.size());
    for (const EffectCoefficient& coefficient : row.coefficients) {
      std::vector<std::string> refused = {"-1.0", ".nan", ".inf"};
      if (coefficient.range == CoefficientRange::kPositive) refused.push_back("0.0");
      for (const std::string& value : refused) {
        const std::string label = std::string(row.name) + "_" + coefficient.key + "_" + value.substr(value.find_first_not_of("-."));
        try {
          load_scene(write(label, scene_with(coefficient.key, value)));
          ADD_FAILURE() << label << ": accepted";
        } catch (const SceneError& error) {
          EXPECT_EQ(error.key(), "effects." + std::string(row.name) + "." + coefficient.key) << error.what();
        }
        ++checked;
      }
    }
  }
  EXPECT_GE(checked, 16);
}

/// The SceneError `load` throws (ADD_FAILURE when it throws none).
template <typename Load>
SceneError scene_error_of(Load load) {
  try {
    load();
  } catch (const SceneError& error) {
    return error;
  }
  ADD_FAILURE() << "no SceneError";
  return SceneError("", "", "");
}

TEST_F(SceneFiles, AFileBeyondTheSizeCapIsRefusedBeforeItIsRead) {
  // A valid scene padded with a comment to one byte past kMaxSceneBytes: refused by its size alone.
  std::string text = kMinimalScene + "# ";
  text += std::string(kMaxSceneBytes + 1 - text.size(), 'x');
  ASSERT_EQ(text.size(), kMaxSceneBytes + 1);
  const std::string path = write("one_byte_too_long", text);
  const SceneError error = scene_error_of([&] { load_scene(path); });
  EXPECT_EQ(error.key(), "(file)");
  EXPECT_NE(std::string(error.what()).find("is 1048577 bytes, beyond the cap of 1048576 bytes"), std::string::npos)
      << error.what();
  text.pop_back();  // exactly at the cap: read, and then refused only for its content (none here)
  EXPECT_NO_THROW(load_scene(write("at_the_cap", text)));
  EXPECT_EQ(read_scene_file(write("at_the_cap", text)).size(), kMaxSceneBytes);
}

TEST_F(SceneFiles, AnEndlessDeviceIsReadNoFurtherThanTheCap) {
  // /dev/zero (as a pipe on stdin would) never ends: read up to the cap, then refused.
  const SceneError error = scene_error_of([] { load_scene("/dev/zero"); });
  EXPECT_EQ(error.key(), "(file)");
  EXPECT_NE(std::string(error.what()).find("holds more than the cap of 1048576 bytes"), std::string::npos)
      << error.what();
}

TEST_F(SceneFiles, ADirectoryIsRefusedAsADirectory) {
  const SceneError error = scene_error_of([&] { load_scene(directory_); });
  EXPECT_EQ(error.key(), "(file)");
  EXPECT_NE(std::string(error.what()).find("is a directory, not a scene file"), std::string::npos) << error.what();
}

TEST_F(SceneFiles, NestingBeyondTheDepthCapIsRefusedByItsKey) {
  // 100 000 maps deep in flow style (~600 kB): refused at level 65 by the key path, before a tree is
  // built (yaml-cpp would stop at its own 2000 levels with a syntax error, after building them).
  std::string deep = kMinimalScene + "deep: ";
  for (int level = 0; level < 100000; ++level) deep += "{a: ";
  deep += "1" + std::string(100000, '}') + "\n";
  const SceneError error = scene_error_of([&] { load_scene(write("deep", deep)); });
  std::string key = "deep";
  for (int level = 2; level <= kMaxSceneDepth; ++level) key += ".a";  // levels 2..64 hold key a
  EXPECT_EQ(error.key(), key);
  EXPECT_NE(std::string(error.what()).find("deeper than the cap of 64 levels"), std::string::npos) << error.what();
  // At the cap the structure passes, and the reader names the unknown key.
  std::string at_cap = kMinimalScene + "deep: ";
  for (int level = 2; level <= kMaxSceneDepth; ++level) at_cap += "[";
  at_cap += std::string(kMaxSceneDepth - 1, ']') + "\n";
  EXPECT_EQ(scene_error_of([&] { load_scene(write("at_cap", at_cap)); }).key(), "deep");
  EXPECT_EQ(scene_error_of([&] { load_scene_text(deep, "<text>"); }).key(), key);  // the same for text
}

TEST_F(SceneFiles, TextThatIsNotUtf8IsRefusedByItsKey) {
  const SceneError in_key = scene_error_of([&] { load_scene(write("key", kMinimalScene + "car\xfft: 1\n")); });
  EXPECT_EQ(in_key.key(), "car\\xfft");
  EXPECT_NE(std::string(in_key.what()).find("is not UTF-8 text"), std::string::npos) << in_key.what();
  const SceneError in_value =
      scene_error_of([&] { load_scene(write("value", edited("minimal test scene", "minimal \xc3\x28 scene"))); });
  EXPECT_EQ(in_value.key(), "description");
  EXPECT_NE(std::string(in_value.what()).find("byte 0xc3 at offset 8"), std::string::npos) << in_value.what();
}

TEST_F(SceneFiles, NonexistentFileNamesTheFile) {
  const std::string path = directory_ + "/no_such_scene.yaml";
  try {
    load_scene(path);
    ADD_FAILURE() << "loaded a file that does not exist";
  } catch (const SceneError& error) {
    EXPECT_EQ(error.file(), path);
    EXPECT_EQ(error.key(), "(file)");
    EXPECT_NE(std::string(error.what()).find(path), std::string::npos);
  }
}

}  // namespace
}  // namespace birkhoff_cart
