// libFuzzer target for the scene reader (apps/scene.hpp): the input is written to a file and
// read with load_scene, as `sewn run` does, and the scene is not run. Every input is either
// read or refused with a SceneError naming the file and a reason; any other exception, a
// crash, a sanitizer report, a hang or an allocation past -malloc_limit_mb is a finding.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "sewn/apps/scene.hpp"

namespace {

[[noreturn]] void finding(const char* what) {
  std::fprintf(stderr, "fuzz_scene: %s\n", what);
  std::abort();
}

const std::string& scratch_file() {
  static const std::string path =
      (std::filesystem::temp_directory_path() / ("sewn-fuzz-scene-" + std::to_string(getpid()) + ".json")).string();
  return path;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string& path = scratch_file();
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    if (!out) finding("cannot write the scratch file");
  }
  try {
    (void)sewn::app::load_scene(path);
  } catch (const sewn::app::SceneError& e) {
    if (e.file() != path || e.reason().empty()) finding("a SceneError without its file or reason");
  }
  return 0;
}
