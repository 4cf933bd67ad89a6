// Line-oriented, machine-readable output: one record per line, flushed at once, safe to call
// from transport callback threads. Tests parse these lines (see testing/gzpeer.py).
#pragma once

#include <google/protobuf/message.h>

#include <cstdint>
#include <string>

namespace peer {

void Line(const std::string &text);

// Protobuf text format on one line (what `MSG`/`RESPONSE` lines carry).
std::string OneLine(const google::protobuf::Message &msg);

// `sha256=<hex> len=<n>` for a serialized payload.
std::string Digest(const char *data, std::size_t size);

// Lowercase hex of a buffer.
std::string Hex(const char *data, std::size_t size);

// CLOCK_MONOTONIC in nanoseconds: the clock the benchmark stamps payloads with, shared with
// Python's time.monotonic_ns().
std::int64_t MonotonicNs();

// Sleep for `seconds` (fractional).
void SleepFor(double seconds);

}  // namespace peer
