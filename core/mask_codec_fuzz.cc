// libFuzzer target for the mask decoder (core/mask_codec.h): any byte string must decode to a
// valid RunMask or to an error, without reading or writing out of bounds (ASan/UBSan), and a
// successful decode must re-encode to exactly the input (the encoding is canonical).
#include <algorithm>
#include <cstdlib>
#include <string>

#include "core/mask_codec.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // decode_mask() is this plus the conversion to Expected, which clang 14 cannot destroy.
  studio::RunMask mask(0, 0);
  const std::string error = studio::detail::decode_mask_into({data, size}, mask);
  if (!error.empty()) {
    if (error.find('\n') != std::string::npos) std::abort();  // one line
    return 0;
  }
  if (!mask.valid()) std::abort();
  // A successful decode had a valid header: byte 1 is the coding.
  const auto again = studio::encode_mask(mask, studio::MaskCoding(data[1]));
  if (again.size() != size || !std::equal(again.begin(), again.end(), data)) std::abort();
  return 0;
}
