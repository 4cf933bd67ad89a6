// pub, echo and relay: the topic side of the peer.
#include <ignition/msgs/Factory.hh>
#include <ignition/transport/Node.hh>

#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include "messages.hh"
#include "modes.hh"
#include "output.hh"

namespace peer {
namespace {

// Waits up to `seconds` for a subscriber; prints CONNECTED or NO_CONNECTIONS.
bool WaitForConnections(const ignition::transport::Node::Publisher &pub, double seconds) {
  const std::int64_t end = MonotonicNs() + static_cast<std::int64_t>(seconds * 1e9);
  while (!pub.HasConnections() && MonotonicNs() < end && !StopRequested()) SleepFor(0.02);
  const bool connected = pub.HasConnections();
  Line(connected ? "CONNECTED" : "NO_CONNECTIONS");
  return connected;
}

}  // namespace

// pub TOPIC TYPE HZ COUNT [TEXTPROTO] [--bytes N] [--wait S] [--settle S] [--linger S]
//     [--wire-type WIRETYPE] [--field "NUMBER TYPE TEXTPROTO"]...
// COUNT <= 0 publishes until stopped; HZ <= 0 publishes back to back. The message is built as
// TYPE (plus each --field, see AppendField) and advertised and sent as WIRETYPE (default TYPE):
// `--wire-type gz.msgs.Clock` puts on the wire what a Harmonic publisher of that type sends.
int RunPub(const Args &args) {
  const std::string topic = args.Word(1, "TOPIC");
  const std::string type = args.Word(2, "TYPE");
  const double hz = ToNumber(args.Word(3, "HZ"), "HZ");
  const long count = static_cast<long>(ToNumber(args.Word(4, "COUNT"), "COUNT"));
  auto msg = MakeMessage(type, args.WordCount() > 5 ? args.Word(5, "TEXTPROTO") : "");
  if (args.Has("bytes")) {
    auto *field = msg->GetDescriptor()->FindFieldByName("data");
    if (!field || field->type() != google::protobuf::FieldDescriptor::TYPE_BYTES) {
      throw UsageError("--bytes needs a type with a bytes field `data`, not " + type);
    }
    const auto size = static_cast<std::size_t>(args.Number("bytes", 0));
    msg->GetReflection()->SetString(msg.get(), field, PatternBytes(size));
  }
  std::string payload;
  msg->SerializeToString(&payload);
  for (const auto &spec : args.All("field")) AppendField(payload, spec);
  const std::string wireType = args.Text("wire-type", type);

  ignition::transport::Node node;
  auto pub = node.Advertise(topic, wireType);
  if (!pub) {
    Line("ERROR advertise failed for " + topic);
    return 1;
  }
  Line("READY");
  Line("PAYLOAD " + Digest(payload.data(), payload.size()));
  // A NEW_CONNECTION can arrive just before the subscriber's ZeroMQ connection is up.
  if (WaitForConnections(pub, args.Number("wait", 5))) SleepFor(args.Number("settle", 0.2));

  long sent = 0;
  for (; (count <= 0 || sent < count) && !StopRequested(); ++sent) {
    pub.PublishRaw(payload, wireType);
    if (hz > 0) SleepFor(1.0 / hz);
  }
  Line("SENT " + std::to_string(sent));
  SleepFor(args.Number("linger", 0.5));
  return 0;
}

// pub-many TYPE HZ TEXTPROTO TOPIC... [--wire-type WIRETYPE]
// One node advertising every TOPIC and publishing the same message on each, all of them once
// per round at HZ rounds a second until stopped, as upstream ros_gz_bridge's test_gz_publisher
// does from one process. Prints READY once all are advertised, then `SENT n` (per topic).
int RunPubMany(const Args &args) {
  const std::string type = args.Word(1, "TYPE");
  const double hz = ToNumber(args.Word(2, "HZ"), "HZ");
  if (hz <= 0) throw UsageError("pub-many needs HZ > 0");
  auto msg = MakeMessage(type, args.Word(3, "TEXTPROTO"));
  std::string payload;
  msg->SerializeToString(&payload);
  const std::string wireType = args.Text("wire-type", type);
  ignition::transport::Node node;
  std::vector<ignition::transport::Node::Publisher> pubs;
  for (std::size_t i = 4; i < args.WordCount(); ++i) {
    pubs.push_back(node.Advertise(args.Word(i, "TOPIC"), wireType));
    if (!pubs.back()) {
      Line("ERROR advertise failed for " + args.Word(i, "TOPIC"));
      return 1;
    }
  }
  if (pubs.empty()) throw UsageError("pub-many needs at least one TOPIC");
  Line("READY");
  const auto period = static_cast<std::int64_t>(1e9 / hz);
  std::int64_t next = MonotonicNs();
  long rounds = 0;
  for (; !StopRequested(); ++rounds) {
    for (auto &pub : pubs) pub.PublishRaw(payload, wireType);
    next += period;
    const std::int64_t wait = next - MonotonicNs();
    if (wait > 0) SleepFor(static_cast<double>(wait) / 1e9);
  }
  Line("SENT " + std::to_string(rounds));
  return 0;
}

// echo TOPIC TYPE SECONDS [--count N] [--sha | --hex] [--wire-type WIRETYPE]
// Prints `MSG <type> <text|hex|sha256=.. len=..>` per message, then `COUNT n BYTES b`. With
// --wire-type it subscribes to WIRETYPE (e.g. gz.msgs.Twist) and decodes the payload as TYPE.
int RunEcho(const Args &args) {
  const std::string topic = args.Word(1, "TOPIC");
  const std::string type = args.Word(2, "TYPE");
  const double seconds = ToNumber(args.Word(3, "SECONDS"), "SECONDS");
  const long wanted = static_cast<long>(args.Number("count", 0));
  const bool sha = args.Has("sha");
  const bool hex = args.Has("hex");
  const std::string wireType = args.Text("wire-type", type);
  const bool decodeAsType = args.Has("wire-type");
  std::atomic<long> received{0};
  std::atomic<long> bytes{0};
  std::mutex printing;

  ignition::transport::Node node;
  auto callback = [&](const char *data, std::size_t size,
                      const ignition::transport::MessageInfo &info) {
    const std::lock_guard<std::mutex> lock(printing);
    if (wanted > 0 && received >= wanted) return;
    std::string body;
    if (sha) {
      body = Digest(data, size);
    } else if (hex) {
      body = Hex(data, size);
    } else {
      auto msg = ignition::msgs::Factory::New(decodeAsType ? type : info.Type());
      body = msg && msg->ParseFromArray(data, static_cast<int>(size)) ? OneLine(*msg)
                                                                      : "UNDECODABLE " + Hex(data, size);
    }
    Line("MSG " + info.Type() + " " + body);
    bytes += static_cast<long>(size);
    ++received;
  };
  if (!node.SubscribeRaw(topic, callback, wireType)) {
    Line("ERROR subscribe failed for " + topic);
    return 1;
  }
  Line("READY");
  const std::int64_t end = MonotonicNs() + static_cast<std::int64_t>(seconds * 1e9);
  while (!StopRequested() && MonotonicNs() < end && (wanted <= 0 || received < wanted)) {
    SleepFor(0.01);
  }
  node.Unsubscribe(topic);
  const std::lock_guard<std::mutex> lock(printing);
  Line("COUNT " + std::to_string(received.load()) + " BYTES " + std::to_string(bytes.load()));
  return 0;
}

// relay IN OUT TYPE SECONDS: republishes every message of IN on OUT unchanged.
int RunRelay(const Args &args) {
  const std::string in = args.Word(1, "IN");
  const std::string out = args.Word(2, "OUT");
  const std::string type = args.Word(3, "TYPE");
  const double seconds = ToNumber(args.Word(4, "SECONDS"), "SECONDS");
  std::atomic<long> relayed{0};

  ignition::transport::Node node;
  auto pub = node.Advertise(out, type);
  if (!pub) {
    Line("ERROR advertise failed for " + out);
    return 1;
  }
  auto callback = [&](const char *data, std::size_t size,
                      const ignition::transport::MessageInfo &info) {
    pub.PublishRaw(std::string(data, size), info.Type());
    ++relayed;
  };
  if (!node.SubscribeRaw(in, callback, type)) {
    Line("ERROR subscribe failed for " + in);
    return 1;
  }
  Line("READY");
  RunFor(seconds);
  node.Unsubscribe(in);
  Line("RELAYED " + std::to_string(relayed.load()));
  return 0;
}

}  // namespace peer
