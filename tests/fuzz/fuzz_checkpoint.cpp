// libFuzzer target for the checkpoint reader (apps/checkpoint.hpp): the input is decoded as a
// checkpoint file. Every input is either read or refused with a CheckpointError naming the
// file and a reason; any other exception, a crash, a sanitizer report, a hang or an allocation
// past -malloc_limit_mb is a finding. Inputs of even length get their checksum recomputed
// first, so that mutations reach the payload's decoder instead of all stopping at the checksum.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "sewn/apps/checkpoint.hpp"

namespace {

[[noreturn]] void finding(const char* what) {
  std::fprintf(stderr, "fuzz_checkpoint: %s\n", what);
  std::abort();
}

constexpr std::size_t header_bytes = 32, checksum_at = 24;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string bytes(reinterpret_cast<const char*>(data), size);
  if (size >= header_bytes && size % 2 == 0) {
    const std::uint64_t sum = sewn::app::fnv1a(std::string_view(bytes).substr(header_bytes));
    std::memcpy(bytes.data() + checksum_at, &sum, sizeof sum);
  }
  try {
    const sewn::app::Checkpoint c = sewn::app::decode_checkpoint(bytes, "input.checkpoint");
    // what was read must be what the format writes back
    if (sewn::app::encode_checkpoint(c).size() != bytes.size()) finding("a checkpoint read back to a different size");
  } catch (const sewn::app::CheckpointError& e) {
    if (e.file() != "input.checkpoint" || e.reason().empty()) finding("a CheckpointError without its file or reason");
  }
  return 0;
}
