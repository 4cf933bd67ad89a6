#include "messages.hh"

#include <google/protobuf/text_format.h>
#include <ignition/msgs/Factory.hh>

#include <atomic>
#include <csignal>
#include <cstdint>

#include "args.hh"
#include "output.hh"

namespace peer {
namespace {
std::atomic<bool> gStop{false};
void OnSignal(int) { gStop = true; }
}  // namespace

std::unique_ptr<google::protobuf::Message> MakeMessage(const std::string &type,
                                                       const std::string &text) {
  auto msg = ignition::msgs::Factory::New(type);
  if (!msg) throw UsageError("unknown message type " + type);
  if (!text.empty() && !google::protobuf::TextFormat::ParseFromString(text, msg.get())) {
    throw UsageError("text does not parse as " + type + ": " + text);
  }
  return msg;
}

std::string PatternBytes(std::size_t size) {
  std::string out(size, '\0');
  std::uint32_t state = 0x9e3779b9u ^ static_cast<std::uint32_t>(size);
  for (auto &byte : out) {
    state ^= state << 13;
    state ^= state >> 17;
    state ^= state << 5;
    byte = static_cast<char>(state & 0xff);
  }
  return out;
}

void InstallStopHandlers() {
  std::signal(SIGINT, OnSignal);
  std::signal(SIGTERM, OnSignal);
}

bool StopRequested() { return gStop; }

void RunFor(double seconds) {
  const std::int64_t end = MonotonicNs() + static_cast<std::int64_t>(seconds * 1e9);
  while (!gStop && (seconds <= 0 || MonotonicNs() < end)) SleepFor(0.02);
}

}  // namespace peer
