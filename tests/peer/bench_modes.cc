// bench-pub and bench-sub: rate and latency over ignition.msgs.Bytes whose data starts with
// the CLOCK_MONOTONIC send time in nanoseconds (int64, little-endian).
#include <ignition/msgs/bytes.pb.h>
#include <ignition/transport/Node.hh>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <string>
#include <vector>

#include "messages.hh"
#include "modes.hh"
#include "output.hh"

namespace peer {
namespace {

constexpr char kBytesType[] = "ignition.msgs.Bytes";
constexpr std::size_t kStampSize = 8;

// Offset of `data` inside a serialized Bytes message (field 2 tag, varint length, data; the
// empty header is not serialized), or npos when the payload is not shaped like that.
std::size_t DataOffset(const char *payload, std::size_t size) {
  constexpr char kDataTag = 0x12;
  if (size < 2 || payload[0] != kDataTag) return std::string::npos;
  std::size_t pos = 1;
  while (pos < size && pos < 11 && (static_cast<unsigned char>(payload[pos]) & 0x80)) ++pos;
  return pos + 1;
}

double Percentile(std::vector<double> &sorted, double fraction) {
  if (sorted.empty()) return 0;
  const auto index = static_cast<std::size_t>(fraction * double(sorted.size() - 1) + 0.5);
  return sorted[std::min(index, sorted.size() - 1)];
}

}  // namespace

// bench-pub TOPIC SIZE SECONDS [--hz HZ] [--wait S]: publishes stamped Bytes of SIZE data
// bytes for SECONDS after the first subscriber connects; prints `SENT n SECONDS s`.
int RunBenchPub(const Args &args) {
  const std::string topic = args.Word(1, "TOPIC");
  const auto size = std::max(kStampSize, static_cast<std::size_t>(ToNumber(args.Word(2, "SIZE"), "SIZE")));
  const double seconds = ToNumber(args.Word(3, "SECONDS"), "SECONDS");
  const double hz = args.Number("hz", 0);
  ignition::msgs::Bytes msg;
  msg.set_data(PatternBytes(size));
  std::string payload;
  msg.SerializeToString(&payload);
  const std::size_t stampAt = payload.size() - size;

  ignition::transport::Node node;
  auto pub = node.Advertise(topic, kBytesType);
  if (!pub) {
    Line("ERROR advertise failed for " + topic);
    return 1;
  }
  Line("READY");
  const std::int64_t waitEnd = MonotonicNs() + static_cast<std::int64_t>(args.Number("wait", 5) * 1e9);
  while (!pub.HasConnections() && MonotonicNs() < waitEnd && !StopRequested()) SleepFor(0.01);
  if (!pub.HasConnections()) {
    Line("NO_CONNECTIONS");
    return 1;
  }
  Line("CONNECTED");
  SleepFor(0.3);
  const std::int64_t start = MonotonicNs();
  const std::int64_t end = start + static_cast<std::int64_t>(seconds * 1e9);
  const std::int64_t period = hz > 0 ? static_cast<std::int64_t>(1e9 / hz) : 0;
  long sent = 0;
  for (std::int64_t next = start; !StopRequested(); ++sent) {
    std::int64_t now = MonotonicNs();
    if (now >= end) break;
    if (period > 0) {
      if (now < next) SleepFor(double(next - now) / 1e9);
      next += period;
      now = MonotonicNs();
    }
    std::memcpy(&payload[stampAt], &now, kStampSize);
    pub.PublishRaw(payload, kBytesType);
  }
  char line[96];
  std::snprintf(line, sizeof line, "SENT %ld SECONDS %.3f", sent, double(MonotonicNs() - start) / 1e9);
  Line(line);
  SleepFor(0.5);
  return 0;
}

// bench-sub TOPIC SECONDS [--count N]: receives stamped Bytes until SECONDS pass or N arrive;
// prints `STATS count=.. bytes=.. seconds=.. rate=.. median_us=.. p99_us=..`, where rate is
// messages per second between the first and the last arrival.
int RunBenchSub(const Args &args) {
  const std::string topic = args.Word(1, "TOPIC");
  const double seconds = ToNumber(args.Word(2, "SECONDS"), "SECONDS");
  const long wanted = static_cast<long>(args.Number("count", 0));
  std::mutex mutex;
  std::vector<double> latenciesUs;
  latenciesUs.reserve(1 << 20);
  long bytes = 0;
  std::int64_t first = 0;
  std::int64_t last = 0;

  ignition::transport::Node node;
  auto callback = [&](const char *data, std::size_t size, const ignition::transport::MessageInfo &) {
    const std::int64_t now = MonotonicNs();
    const std::size_t at = DataOffset(data, size);
    if (at == std::string::npos || at + kStampSize > size) return;
    std::int64_t stamp = 0;
    std::memcpy(&stamp, data + at, kStampSize);
    const std::lock_guard<std::mutex> lock(mutex);
    if (latenciesUs.empty()) first = now;
    last = now;
    latenciesUs.push_back(double(now - stamp) / 1e3);
    bytes += static_cast<long>(size);
  };
  if (!node.SubscribeRaw(topic, callback, kBytesType)) {
    Line("ERROR subscribe failed for " + topic);
    return 1;
  }
  Line("READY");
  const std::int64_t end = MonotonicNs() + static_cast<std::int64_t>(seconds * 1e9);
  while (!StopRequested() && MonotonicNs() < end) {
    {
      const std::lock_guard<std::mutex> lock(mutex);
      if (wanted > 0 && static_cast<long>(latenciesUs.size()) >= wanted) break;
    }
    SleepFor(0.01);
  }
  node.Unsubscribe(topic);
  const std::lock_guard<std::mutex> lock(mutex);
  const long count = static_cast<long>(latenciesUs.size());
  const double span = double(last - first) / 1e9;
  const double rate = count > 1 && span > 0 ? double(count - 1) / span : 0;
  std::sort(latenciesUs.begin(), latenciesUs.end());
  char line[256];
  std::snprintf(line, sizeof line,
                "STATS count=%ld bytes=%ld seconds=%.3f rate=%.1f median_us=%.1f p99_us=%.1f", count,
                bytes, span, rate, Percentile(latenciesUs, 0.5), Percentile(latenciesUs, 0.99));
  Line(line);
  return 0;
}

}  // namespace peer
