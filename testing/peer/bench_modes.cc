// The benchmark modes. bench-pub and bench-sub measure the transport alone with
// ignition.msgs.Bytes whose data starts with the CLOCK_MONOTONIC send time in nanoseconds
// (int64, little-endian). kind-pub and kind-sub are the Gazebo end of a bridge benchmark: a
// typed message read from a file, its send time at a stamp path (see StampPath).
#include <ignition/msgs/bytes.pb.h>
#include <ignition/transport/Node.hh>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "flood.hh"
#include "messages.hh"
#include "modes.hh"
#include "output.hh"
#include "stamp.hh"

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

// Advertises TOPIC as `type`, waits up to --wait seconds (default 5) for a subscriber, then
// calls `send(now)` back to back, or every 1/HZ s with --hz, for SECONDS; prints READY,
// CONNECTED, START and `SENT n SECONDS s`. `beforeStart`, when given, runs just before START.
// Returns the exit status.
int PublishFor(const Args &args, const std::string &topic, const std::string &type,
               double seconds, const std::function<void(ignition::transport::Node::Publisher &,
                                                        std::int64_t)> &send,
               const std::function<void()> &beforeStart = nullptr) {
  const double hz = args.Number("hz", 0);
  ignition::transport::Node node;
  auto pub = node.Advertise(topic, type);
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
  SleepFor(args.Number("settle", 0.3));
  if (beforeStart) beforeStart();
  Line("START");
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
    send(pub, now);
  }
  char line[96];
  std::snprintf(line, sizeof line, "SENT %ld SECONDS %.3f", sent, double(MonotonicNs() - start) / 1e9);
  Line(line);
  SleepFor(0.5);
  return 0;
}

// Latencies and arrival times of one subscriber, up to `limit` messages (0: no limit),
// reported as a STATS line: rate is messages per second between the first and the last arrival.
class Recorder {
 public:
  explicit Recorder(long limit) : limit_(limit) { latenciesUs_.reserve(1 << 20); }

  // `arrived`: when the payload reached the callback, before any parsing.
  void Record(std::int64_t stamp, std::size_t size, std::int64_t arrived) {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (limit_ > 0 && static_cast<long>(latenciesUs_.size()) >= limit_) return;
    if (latenciesUs_.empty()) first_ = arrived;
    last_ = arrived;
    latenciesUs_.push_back(double(arrived - stamp) / 1e3);
    bytes_ += static_cast<long>(size);
  }

  long Count() {
    const std::lock_guard<std::mutex> lock(mutex_);
    return static_cast<long>(latenciesUs_.size());
  }

  void Report() {
    const std::lock_guard<std::mutex> lock(mutex_);
    const long count = static_cast<long>(latenciesUs_.size());
    const double span = double(last_ - first_) / 1e9;
    const double rate = count > 1 && span > 0 ? double(count - 1) / span : 0;
    std::sort(latenciesUs_.begin(), latenciesUs_.end());
    char line[256];
    std::snprintf(line, sizeof line,
                  "STATS count=%ld bytes=%ld seconds=%.3f rate=%.1f median_us=%.1f p99_us=%.1f",
                  count, bytes_, span, rate, Percentile(latenciesUs_, 0.5),
                  Percentile(latenciesUs_, 0.99));
    Line(line);
  }

 private:
  const long limit_;
  std::mutex mutex_;
  std::vector<double> latenciesUs_;
  long bytes_ = 0;
  std::int64_t first_ = 0;
  std::int64_t last_ = 0;
};

// Subscribes to TOPIC as `type` and hands every payload to `record` until SECONDS pass or
// --count N arrived; prints READY, MATCHED once a publisher is known, then the STATS line.
int RecordFor(const Args &args, const std::string &topic, const std::string &type, double seconds,
              const std::function<void(Recorder &, const char *, std::size_t)> &record) {
  const long wanted = static_cast<long>(args.Number("count", 0));
  Recorder recorder(wanted);
  ignition::transport::Node node;
  auto callback = [&](const char *data, std::size_t size, const ignition::transport::MessageInfo &) {
    record(recorder, data, size);
  };
  if (!node.SubscribeRaw(topic, callback, type)) {
    Line("ERROR subscribe failed for " + topic);
    return 1;
  }
  Line("READY");
  bool matched = false;
  const std::int64_t end = MonotonicNs() + static_cast<std::int64_t>(seconds * 1e9);
  while (!StopRequested() && MonotonicNs() < end && (wanted <= 0 || recorder.Count() < wanted)) {
    if (!matched) {
      std::vector<ignition::transport::MessagePublisher> publishers;
      if (node.TopicInfo(topic, publishers) && !publishers.empty()) {
        matched = true;
        Line("MATCHED");
      }
    }
    SleepFor(0.01);
  }
  node.Unsubscribe(topic);
  recorder.Report();
  return 0;
}

}  // namespace

// bench-pub TOPIC SIZE SECONDS [--hz HZ] [--wait S]: publishes stamped Bytes of SIZE data
// bytes for SECONDS after the first subscriber connects.
int RunBenchPub(const Args &args) {
  const auto size = std::max(kStampSize, static_cast<std::size_t>(ToNumber(args.Word(2, "SIZE"), "SIZE")));
  ignition::msgs::Bytes msg;
  msg.set_data(PatternBytes(size));
  std::string payload;
  msg.SerializeToString(&payload);
  const std::size_t stampAt = payload.size() - size;
  return PublishFor(args, args.Word(1, "TOPIC"), kBytesType, ToNumber(args.Word(3, "SECONDS"), "SECONDS"),
                    [&](ignition::transport::Node::Publisher &pub, std::int64_t now) {
                      std::memcpy(&payload[stampAt], &now, kStampSize);
                      pub.PublishRaw(payload, kBytesType);
                    });
}

// bench-sub TOPIC SECONDS [--count N]: receives stamped Bytes.
int RunBenchSub(const Args &args) {
  return RecordFor(args, args.Word(1, "TOPIC"), kBytesType, ToNumber(args.Word(2, "SECONDS"), "SECONDS"),
                   [](Recorder &recorder, const char *data, std::size_t size) {
                     const std::int64_t arrived = MonotonicNs();
                     const std::size_t at = DataOffset(data, size);
                     if (at == std::string::npos || at + kStampSize > size) return;
                     std::int64_t stamp = 0;
                     std::memcpy(&stamp, data + at, kStampSize);
                     recorder.Record(stamp, size, arrived);
                   });
}

// kind-pub TOPIC TYPE FILE SECONDS --stamp PATH [--hz HZ] [--wait S] [--wire-type WIRETYPE]
// [--flood TOPIC ...]: publishes the TYPE message serialized in FILE with the send time written
// at PATH, serialized anew for every message as a simulator does, advertised and sent as
// WIRETYPE (default TYPE). With --flood (see flood.hh) the same process also publishes a second
// stream, from --flood-lead seconds before START until 0.5 s after SENT, then prints FLOOD_SENT.
int RunKindPub(const Args &args) {
  const std::string type = args.Word(2, "TYPE");
  auto msg = MakeMessage(type, "");
  if (!msg->ParseFromString(ReadFile(args.Word(3, "FILE")))) {
    throw UsageError(args.Word(3, "FILE") + " does not parse as " + type);
  }
  const StampPath stamp(*msg, args.Text("stamp", ""));
  const std::string wireType = args.Text("wire-type", type);
  std::string payload;
  std::unique_ptr<Flood> flood;
  if (args.Has("flood")) flood = std::make_unique<Flood>(args);
  const int status = PublishFor(
      args, args.Word(1, "TOPIC"), wireType, ToNumber(args.Word(4, "SECONDS"), "SECONDS"),
      [&](ignition::transport::Node::Publisher &pub, std::int64_t now) {
        stamp.Write(*msg, now);
        msg->SerializeToString(&payload);
        pub.PublishRaw(payload, wireType);
      },
      [&] {
        if (flood) flood->WaitUntilFlowing(args.Number("wait", 5));
      });
  if (flood) flood->Stop();
  return status;
}

// kind-sub TOPIC TYPE SECONDS --stamp PATH [--count N] [--wire-type WIRETYPE]: parses every
// message as TYPE and records the send time at PATH; payloads that do not parse are not counted.
int RunKindSub(const Args &args) {
  const std::string type = args.Word(2, "TYPE");
  auto msg = MakeMessage(type, "");
  const StampPath stamp(*msg, args.Text("stamp", ""));
  return RecordFor(args, args.Word(1, "TOPIC"), args.Text("wire-type", type),
                   ToNumber(args.Word(3, "SECONDS"), "SECONDS"),
                   [&](Recorder &recorder, const char *data, std::size_t size) {
                     // Latency ends on arrival: parsing the whole message to find the stamp
                     // is the benchmark's cost, not the transport's.
                     const std::int64_t arrived = MonotonicNs();
                     // One callback thread per subscription: the parsed message is reused.
                     if (!msg->ParseFromArray(data, static_cast<int>(size))) return;
                     const std::int64_t sent = stamp.Read(*msg);
                     if (sent >= 0) recorder.Record(sent, size, arrived);
                   });
}

}  // namespace peer
