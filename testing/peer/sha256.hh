// SHA-256 (FIPS 180-4) of a byte buffer, so large payloads can be compared by digest
// across processes without printing megabytes.
#pragma once

#include <cstddef>
#include <string>

namespace peer {

// Lowercase hex digest of `size` bytes at `data`.
std::string Sha256Hex(const char *data, std::size_t size);

}  // namespace peer
