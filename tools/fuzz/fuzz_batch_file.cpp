// libFuzzer target: batch-file text -> parse_batch_json. Any input must either parse or throw InputError; crashes,
// sanitizer reports, hangs and any other exception are bugs. Mesh paths resolve against tests/data.
#include "batchcol/io.hpp"

#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  // Keep the fuzzer away from pseudo-files (/proc/kcore is a "regular file" of 128 TB); this target is about the
  // parser, real mesh files are the other target's job.
  for (const char* system_dir : {"/proc", "/sys", "/dev"})
    if (text.find(system_dir) != std::string::npos) return 0;
  try {
    const batchcol::BatchFile file = batchcol::parse_batch_json(text, "fuzz.json", BATCHCOL_FUZZ_DATA_DIR);
    batchcol::QueryOptions options;
    file.apply_to(options);
    // Whatever was accepted must be valid: every pair refers to an existing shape.
    for (std::size_t i = 0; i < file.pairs.size(); ++i)
      if (file.pairs.shape_a[i] >= file.shapes.size() || file.pairs.shape_b[i] >= file.shapes.size()) __builtin_trap();
  } catch (const batchcol::InputError&) {
  }
  return 0;
}
