#include "core/scene/scene.hpp"

#include <gtest/gtest.h>

#include <cctype>
#include <cstdio>
#include <fstream>

#include "core/error.hpp"
#include "core/scene/scene_toml.hpp"

namespace hapticsim {
namespace {

// Runs `action`, expects an Error, and returns its message.
template <typename F>
std::string ErrorMessage(F action) {
  try {
    action();
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "no hapticsim::Error thrown";
  return "";
}

std::string WriteTemp(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + name;
  std::ofstream(path) << text;
  return path;
}

TEST(Scene, DefaultsAreThePapersScene) {
  const Scene scene;
  EXPECT_EQ(scene.mesh.nodes, 13);
  EXPECT_DOUBLE_EQ(scene.mesh.edge_m, 0.25);
  EXPECT_DOUBLE_EQ(scene.material.youngs_modulus_pa, 10e3);
  EXPECT_DOUBLE_EQ(scene.material.poisson_ratio, 0.45);
  EXPECT_DOUBLE_EQ(scene.material.density_kg_m3, 1000);
  EXPECT_DOUBLE_EQ(scene.material.damping_per_s, 10);
  EXPECT_DOUBLE_EQ(scene.input.amplitude_m, 0.01);
  EXPECT_DOUBLE_EQ(scene.input.frequency_hz, 1.0);
  EXPECT_EQ(scene.input.waveform, Waveform::kPress);
  EXPECT_DOUBLE_EQ(scene.solver.dt_s, 1e-3);
  EXPECT_EQ(scene.num_steps(), 1000);
  EXPECT_NO_THROW(ValidateScene(scene));
}

struct BadValue {
  const char* assignment;
  const char* must_mention;
  friend void PrintTo(const BadValue& bad, std::ostream* out) { *out << bad.assignment; }
};

class RejectsBadValue : public ::testing::TestWithParam<BadValue> {};

TEST_P(RejectsBadValue, WithAMessageNamingKeyAndRange) {
  Scene scene;
  const std::string message =
      ErrorMessage([&] { ApplySceneOverrides(&scene, {GetParam().assignment}); });
  EXPECT_NE(message.find(GetParam().must_mention), std::string::npos) << message;
}

INSTANTIATE_TEST_SUITE_P(
    Values, RejectsBadValue,
    ::testing::Values(BadValue{"material.poisson_ratio=0.5", "(-1, 0.5)"},
                      BadValue{"material.poisson_ratio=-1", "material.poisson_ratio"},
                      BadValue{"material.youngs_modulus=0",
                               "material.youngs_modulus must be finite and > 0"},
                      BadValue{"material.density=-3", "material.density"},
                      BadValue{"mesh.nodes=1", "mesh.nodes must be a whole number from 2"},
                      BadValue{"mesh.nodes=12.5", "mesh.nodes"},
                      BadValue{"solver.dt=0", "solver.dt must be finite and > 0"},
                      BadValue{"solver.dt=nan", "solver.dt"},
                      BadValue{"material.damping=inf", "material.damping"},
                      BadValue{"geometry.spacing_m=nan", "geometry.spacing_m must be finite"},
                      BadValue{"geometry.spacing_m=-0.005", "geometry.spacing_m"},
                      BadValue{"input.waveform=square", "\"press\", \"sine\" or \"stroke\""},
                      BadValue{"input.frequency=abc", "input.frequency = 'abc' is not a number"},
                      BadValue{"input.amplitude=0.3", "below mesh.edge"},
                      BadValue{"material.stiffness=3", "unknown scene key 'material.stiffness'"},
                      BadValue{"poisson_ratio", "section.key=value"}),
    [](const ::testing::TestParamInfo<BadValue>& info) {
      std::string name;
      for (const char* c = info.param.assignment; *c; ++c) name += std::isalnum(*c) ? *c : '_';
      return name;
    });

TEST(Scene, EveryKeyRoundTripsThroughItsText) {
  Scene scene;
  ApplySceneOverrides(&scene, {"material.poisson_ratio=0.49", "input.waveform=sine",
                               "mesh.nodes=25", "solver.dt=0.00025"});
  for (const SceneKeyInfo& key : SceneKeys()) {
    Scene copy;
    SetSceneValue(&copy, key.name, GetSceneValue(scene, key.name));
    EXPECT_EQ(GetSceneValue(copy, key.name), GetSceneValue(scene, key.name)) << key.name;
  }
}

TEST(SceneFile, TomlRoundTripsTheEffectiveScene) {
  Scene scene;
  ApplySceneOverrides(&scene, {"material.youngs_modulus=15000", "input.frequency=1.25"});
  const std::string path = WriteTemp("roundtrip.toml", FormatSceneToml(scene));
  const Scene loaded = LoadSceneFile(path);
  EXPECT_EQ(FormatSceneToml(loaded), FormatSceneToml(scene));
  EXPECT_DOUBLE_EQ(loaded.material.youngs_modulus_pa, 15000);
}

TEST(SceneFile, IntegerValuesAreAcceptedForRealKeys) {
  const std::string path = WriteTemp("ints.toml", "[material]\nyoungs_modulus = 20000\n");
  EXPECT_DOUBLE_EQ(LoadSceneFile(path).material.youngs_modulus_pa, 20000);
}

TEST(SceneFile, UnknownKeyIsNamedWithFileAndLine) {
  const std::string path = WriteTemp("unknown.toml", "[mesh]\nnodes = 13\nsize = 3\n");
  const std::string message = ErrorMessage([&] { LoadSceneFile(path); });
  EXPECT_NE(message.find("unknown.toml:3"), std::string::npos) << message;
  EXPECT_NE(message.find("mesh.size"), std::string::npos) << message;
}

TEST(SceneFile, OutOfRangeValueIsNamed) {
  const std::string path = WriteTemp("range.toml", "[material]\npoisson_ratio = 0.7\n");
  const std::string message = ErrorMessage([&] { LoadSceneFile(path); });
  EXPECT_NE(message.find("material.poisson_ratio"), std::string::npos) << message;
  EXPECT_NE(message.find("(-1, 0.5)"), std::string::npos) << message;
}

TEST(SceneFile, MalformedFileSaysWhere) {
  const std::string path = WriteTemp("broken.toml", "[mesh\nnodes = 13\n");
  const std::string message = ErrorMessage([&] { LoadSceneFile(path); });
  EXPECT_NE(message.find("broken.toml:1"), std::string::npos) << message;
}

TEST(SceneFile, WrongTypeIsNamed) {
  const std::string path = WriteTemp("type.toml", "[input]\nwaveform = true\n");
  const std::string message = ErrorMessage([&] { LoadSceneFile(path); });
  EXPECT_NE(message.find("input.waveform"), std::string::npos) << message;
}

TEST(SceneFile, MissingFileIsNamed) {
  const std::string message = ErrorMessage([] { LoadSceneFile("/nonexistent/scene.toml"); });
  EXPECT_NE(message.find("/nonexistent/scene.toml"), std::string::npos) << message;
}

TEST(SceneFile, KeyOutsideASectionIsRejected) {
  const std::string path = WriteTemp("flat.toml", "nodes = 13\n");
  const std::string message = ErrorMessage([&] { LoadSceneFile(path); });
  EXPECT_NE(message.find("'nodes' must be a section"), std::string::npos) << message;
}

}  // namespace
}  // namespace hapticsim

namespace hapticsim {
namespace {

struct BadAdaptivity {
  std::vector<std::string> assignments;
  const char* must_mention;
};

class RejectsBadAdaptivity : public ::testing::TestWithParam<BadAdaptivity> {};

TEST_P(RejectsBadAdaptivity, WithAMessageNamingTheKey) {
  Scene scene;
  const std::string message =
      ErrorMessage([&] { ApplySceneOverrides(&scene, GetParam().assignments); });
  EXPECT_NE(message.find(GetParam().must_mention), std::string::npos) << message;
}

INSTANTIATE_TEST_SUITE_P(
    Configurations, RejectsBadAdaptivity,
    ::testing::Values(
        BadAdaptivity{{"adaptivity.primary_size=12"},
                      "adaptivity.primary_size = 12 covers the whole object"},
        BadAdaptivity{{"adaptivity.primary_size=2", "adaptivity.secondary_lod=5"},
                      "adaptivity.secondary_lod = 5 does not divide"},
        BadAdaptivity{{"adaptivity.secondary_rate=0"}, "adaptivity.secondary_rate"},
        BadAdaptivity{{"adaptivity.secondary_rate=-600"}, "adaptivity.secondary_rate"},
        BadAdaptivity{{"adaptivity.secondary_rate=nan"}, "adaptivity.secondary_rate"},
        BadAdaptivity{{"adaptivity.secondary_rate=600.5"}, "adaptivity.secondary_rate"},
        BadAdaptivity{{"adaptivity.primary_size=2", "adaptivity.secondary_rate=1200"},
                      "at most the primary rate"},
        BadAdaptivity{{"adaptivity.primary_size=-1"}, "adaptivity.primary_size"},
        BadAdaptivity{{"adaptivity.primary_size=2", "solver.dt=0.0003"},
                      "1 / (a whole number of Hz)"},
        BadAdaptivity{{"adaptivity.coupling=magic"}, "\"displacement\" or \"force\""}),
    [](const ::testing::TestParamInfo<BadAdaptivity>& info) {
      return "case" + std::to_string(info.index);
    });

}  // namespace
}  // namespace hapticsim
