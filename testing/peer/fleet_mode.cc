// pub-fleet: one process publishing a whole simulated fleet, as a simulator does.
#include <ignition/msgs/Factory.hh>
#include <ignition/transport/Node.hh>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "messages.hh"
#include "modes.hh"
#include "output.hh"

namespace peer {
namespace {

// A topic the fleet publishes on: its payload, serialized once, and its schedule.
struct Published {
  std::string topic;
  std::string type;
  std::string payload;
  std::int64_t periodNs = 0;
  std::int64_t nextNs = 0;
  long sent = 0;
  ignition::transport::Node::Publisher publisher;
};

// A topic the fleet subscribes to (the robots' commands): what arrived, counted.
struct Subscribed {
  std::string topic;
  std::string type;
  std::atomic<long> received{0};
};

// How far behind its schedule a topic may fall before it skips ahead instead of catching up.
constexpr std::int64_t kMaxLagNs = 1'000'000'000;

// One line of the spec: `pub TYPE HZ TOPIC TEXTPROTO` or `sub TYPE TOPIC`; `#` comments.
void ParseLine(const std::string &line, std::size_t number, std::vector<Published> &pubs,
               std::vector<std::unique_ptr<Subscribed>> &subs) {
  std::istringstream words(line);
  std::string kind;
  if (!(words >> kind) || kind[0] == '#') return;
  const std::string where = "spec line " + std::to_string(number) + ": ";
  std::string type, topic;
  if (kind == "pub") {
    std::string hzText;
    if (!(words >> type >> hzText >> topic)) throw UsageError(where + "pub needs TYPE HZ TOPIC");
    const double hz = ToNumber(hzText, "HZ");
    if (hz <= 0) throw UsageError(where + "HZ must be > 0");
    std::string text;
    std::getline(words, text);
    Published pub;
    pub.topic = topic;
    pub.type = type;
    MakeMessage(type, text)->SerializeToString(&pub.payload);
    pub.periodNs = static_cast<std::int64_t>(1e9 / hz);
    pubs.push_back(std::move(pub));
  } else if (kind == "sub") {
    if (!(words >> type >> topic)) throw UsageError(where + "sub needs TYPE TOPIC");
    auto sub = std::make_unique<Subscribed>();
    sub->topic = topic;
    sub->type = type;
    subs.push_back(std::move(sub));
  } else {
    throw UsageError(where + "starts with " + kind + ", not pub or sub");
  }
}

}  // namespace

// pub-fleet SPECFILE SECONDS
// One node advertising every `pub TYPE HZ TOPIC TEXTPROTO` line of SPECFILE and publishing its
// message at its own rate, whether or not anyone subscribes, and subscribing to every
// `sub TYPE TOPIC` line. SECONDS <= 0 runs until stopped. Prints READY once every endpoint
// exists, `FIRST TOPIC <text>` on the first message of each subscribed topic, and at the end
// `SENT TOPIC n` per published topic, `RECEIVED TOPIC n` per subscribed topic, then DONE.
int RunPubFleet(const Args &args) {
  const std::string spec = ReadFile(args.Word(1, "SPECFILE"));
  const double seconds = ToNumber(args.Word(2, "SECONDS"), "SECONDS");
  std::vector<Published> pubs;
  std::vector<std::unique_ptr<Subscribed>> subs;
  std::istringstream lines(spec);
  std::string line;
  for (std::size_t number = 1; std::getline(lines, line); ++number) {
    ParseLine(line, number, pubs, subs);
  }
  if (pubs.empty() && subs.empty()) throw UsageError("pub-fleet: the spec names no topic");

  ignition::transport::Node node;
  for (auto &pub : pubs) {
    pub.publisher = node.Advertise(pub.topic, pub.type);
    if (!pub.publisher) {
      Line("ERROR advertise failed for " + pub.topic);
      return 1;
    }
  }
  for (auto &sub : subs) {
    Subscribed *target = sub.get();
    auto callback = [target](const char *data, std::size_t size,
                             const ignition::transport::MessageInfo &) {
      if (target->received++ > 0) return;
      auto msg = ignition::msgs::Factory::New(target->type);
      const bool parsed = msg && msg->ParseFromArray(data, static_cast<int>(size));
      Line("FIRST " + target->topic + " " + (parsed ? OneLine(*msg) : "UNDECODABLE " + Hex(data, size)));
    };
    if (!node.SubscribeRaw(sub->topic, callback, sub->type)) {
      Line("ERROR subscribe failed for " + sub->topic);
      return 1;
    }
  }
  Line("READY");

  const std::int64_t start = MonotonicNs();
  const std::int64_t end = seconds > 0 ? start + static_cast<std::int64_t>(seconds * 1e9) : INT64_MAX;
  for (auto &pub : pubs) pub.nextNs = start;
  while (!StopRequested()) {
    std::int64_t now = MonotonicNs();
    if (now >= end) break;
    std::int64_t wake = end;
    for (auto &pub : pubs) {
      if (pub.nextNs <= now) {
        pub.publisher.PublishRaw(pub.payload, pub.type);
        ++pub.sent;
        pub.nextNs += pub.periodNs;
        if (now - pub.nextNs > kMaxLagNs) pub.nextNs = now + pub.periodNs;
      }
      wake = std::min(wake, pub.nextNs);
    }
    now = MonotonicNs();
    if (wake > now) SleepFor(static_cast<double>(wake - now) / 1e9);
  }
  for (const auto &pub : pubs) Line("SENT " + pub.topic + " " + std::to_string(pub.sent));
  for (const auto &sub : subs) Line("RECEIVED " + sub->topic + " " + std::to_string(sub->received.load()));
  Line("DONE");
  return 0;
}

}  // namespace peer
