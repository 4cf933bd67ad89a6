#include "messages.hh"

#include <google/protobuf/text_format.h>
#include <ignition/msgs/Factory.hh>

#include <atomic>
#include <csignal>
#include <cstdint>
#include <fstream>
#include <iterator>

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

namespace {
void AppendVarint(std::string &out, std::uint64_t value) {
  while (value >= 0x80) {
    out.push_back(static_cast<char>((value & 0x7f) | 0x80));
    value >>= 7;
  }
  out.push_back(static_cast<char>(value));
}
}  // namespace

void AppendField(std::string &payload, const std::string &spec) {
  const auto typeStart = spec.find(' ');
  const auto textStart = typeStart == std::string::npos ? typeStart : spec.find(' ', typeStart + 1);
  if (textStart == std::string::npos) throw UsageError("--field needs NUMBER TYPE TEXT: " + spec);
  const double number = ToNumber(spec.substr(0, typeStart), "--field NUMBER");
  if (number < 1 || number != static_cast<std::uint32_t>(number)) {
    throw UsageError("--field NUMBER must be a positive integer: " + spec);
  }
  auto msg = MakeMessage(spec.substr(typeStart + 1, textStart - typeStart - 1), spec.substr(textStart + 1));
  std::string body;
  msg->SerializeToString(&body);
  constexpr std::uint64_t kLengthDelimited = 2;
  AppendVarint(payload, (static_cast<std::uint64_t>(number) << 3) | kLengthDelimited);
  AppendVarint(payload, body.size());
  payload += body;
}

std::string ReadFile(const std::string &path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw UsageError("cannot read " + path);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
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
