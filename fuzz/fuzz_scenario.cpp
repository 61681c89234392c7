// Fuzz target: a scenario file (pullout/config/scenario.hpp), read with load_scenario on top of the
// shipped config (config/pullout.yaml), as `pullout plan` and the tests read one.
//
// load_scenario reads a file, so each input is written to <temp>/scenarios/input.yaml. The temp
// directory also holds what the project's scenarios refer to: maps/ (a link to tests/maps, for
// `map: ../maps/straight_shoulder.osm`) and a small ROS map_server grid, scenarios/lot.yaml and
// lot.pgm (for `grid: {map: lot.yaml}`). An input that begins as a PGM image does ("P2" or "P5")
// is the image instead: written to scenarios/input.pgm and read through a fixed scenario whose
// grid is the map_server file image.yaml naming it (the PGM reader gets the fuzzed bytes). A
// ConfigError is the expected answer to a bad file; anything else escaping, a crash or a sanitizer
// report is a defect.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "pullout/config/config.hpp"
#include "pullout/config/scenario.hpp"

namespace {

namespace fs = std::filesystem;

struct Fixture {
  Fixture() : base(pullout::load_config(PULLOUT_SOURCE_DIR "/config/pullout.yaml")) {
    const char* tmp = std::getenv("TMPDIR");
    std::string pattern = std::string(tmp != nullptr && *tmp != '\0' ? tmp : "/tmp") + "/fuzz_scenario.XXXXXX";
    if (mkdtemp(pattern.data()) == nullptr) std::abort();
    dir = pattern;
    fs::create_directories(dir / "scenarios");
    fs::create_directory_symlink(fs::path(PULLOUT_SOURCE_DIR) / "tests" / "maps", dir / "maps");
    std::ofstream(dir / "scenarios" / "lot.pgm", std::ios::binary)
        << "P5\n4 3\n255\n"
        << std::string("\x00\xff\xff\xff", 4) << std::string("\xff\x80\xff\xff", 4)
        << std::string("\xff\xff\xff\x00", 4);
    std::ofstream(dir / "scenarios" / "lot.yaml") << "image: lot.pgm\nresolution: 0.5\norigin: [1.0, 2.0, 0.0]\n"
                                                  << "occupied_thresh: 0.65\nfree_thresh: 0.196\nnegate: 0\n";
    std::ofstream(dir / "scenarios" / "image.yaml") << "image: input.pgm\nresolution: 0.5\norigin: [0.0, 0.0, 0.0]\n"
                                                    << "occupied_thresh: 0.65\nfree_thresh: 0.196\nnegate: 0\n";
    std::ofstream(dir / "scenarios" / "image_scenario.yaml")
        << "start: {x: 1.0, y: 1.0, yaw: 0.0}\ngoal: {x: 2.0, y: 1.0, yaw: 0.0}\ngrid: {map: image.yaml}\n";
    input = (dir / "scenarios" / "input.yaml").string();
    image = (dir / "scenarios" / "input.pgm").string();
    image_scenario = (dir / "scenarios" / "image_scenario.yaml").string();
  }
  ~Fixture() {
    std::error_code ignored;
    fs::remove_all(dir, ignored);
  }
  Fixture(const Fixture&) = delete;
  Fixture& operator=(const Fixture&) = delete;

  pullout::Config base;
  fs::path dir;
  std::string input;
  std::string image;
  std::string image_scenario;
};

Fixture& fixture() {
  static Fixture f;
  return f;
}

}  // namespace

// The fixture is made before the first input, so that its cost is not counted in -timeout.
extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  fixture();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Fixture& f = fixture();
  const bool pgm = size >= 2 && data[0] == 'P' && (data[1] == '2' || data[1] == '5');
  {
    std::ofstream out(pgm ? f.image : f.input, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  try {
    const pullout::Scenario scenario = pullout::load_scenario(pgm ? f.image_scenario : f.input, f.base);
  } catch (const pullout::ConfigError&) {
    // the expected answer to a bad file
  }
  return 0;
}
