// Building messages of any ignition-msgs8 type by name, and the deterministic filler used for
// large `ignition.msgs.Bytes` payloads.
#pragma once

#include <google/protobuf/message.h>

#include <memory>
#include <string>

namespace peer {

// A message of `type` (via the msgs factory), filled from protobuf text format when `text` is
// not empty. Throws UsageError for an unknown type or text that does not parse.
std::unique_ptr<google::protobuf::Message> MakeMessage(const std::string &type,
                                                       const std::string &text);

// Appends a length-delimited field to a serialized message: `spec` is `NUMBER TYPE TEXTPROTO`,
// the field number and a message of an ignition-msgs8 type built from text. This is how the peer
// writes fields its own (Fortress) definitions lack, e.g. the covariances of a Harmonic
// `gz.msgs.IMU`, whose numbers differ from `ignition.msgs.IMU`.
void AppendField(std::string &payload, const std::string &spec);

// The contents of the file at `path`; throws UsageError when it cannot be read.
std::string ReadFile(const std::string &path);

// `size` pseudo-random bytes (xorshift), so a corrupted or truncated copy cannot pass a digest
// check by accident the way a constant fill could.
std::string PatternBytes(std::size_t size);

// Waits until `stop` is set by SIGINT/SIGTERM or `seconds` have passed (<= 0: until stopped).
void RunFor(double seconds);
bool StopRequested();
void InstallStopHandlers();

}  // namespace peer
