#include "flood.hh"

#include <string>

#include "messages.hh"
#include "output.hh"

namespace peer {
namespace {

// How long Stop waits after the last publish before the count is printed.
constexpr double kFlushSeconds = 0.3;
// How long the flood waits once a subscriber is known, before its first message: discovery
// tells of the subscriber before its ZeroMQ subscription reaches this publisher, and what is
// sent in between is dropped (as pub's --settle does).
constexpr double kSettleSeconds = 0.2;

std::unique_ptr<google::protobuf::Message> ReadMessage(const Args &args) {
  const std::string type = args.Text("flood-type", "");
  auto msg = MakeMessage(type, "");
  const std::string file = args.Text("flood-file", "");
  if (!msg->ParseFromString(ReadFile(file))) throw UsageError(file + " does not parse as " + type);
  return msg;
}

}  // namespace

Flood::Flood(const Args &args)
    : msg_(ReadMessage(args)),
      stamp_(*msg_, args.Text("flood-stamp", "")),
      wireType_(args.Text("flood-wire-type", args.Text("flood-type", ""))),
      hz_(args.Number("flood-hz", 0)),
      lead_(args.Number("flood-lead", 1)) {
  const std::string topic = args.Text("flood", "");
  pub_ = node_.Advertise(topic, wireType_);
  if (!pub_) throw UsageError("cannot advertise the flood topic " + topic);
  thread_ = std::thread([this] { Run(); });
}

Flood::~Flood() { Stop(); }

void Flood::Run() {
  while (!pub_.HasConnections() && !stop_) SleepFor(0.01);
  SleepFor(kSettleSeconds);
  const std::int64_t period = hz_ > 0 ? static_cast<std::int64_t>(1e9 / hz_) : 0;
  std::string payload;
  std::int64_t next = MonotonicNs();
  started_ = next;
  while (!stop_) {
    std::int64_t now = MonotonicNs();
    if (period > 0) {
      if (now < next) SleepFor(double(next - now) / 1e9);
      next += period;
      now = MonotonicNs();
    }
    stamp_.Write(*msg_, now);
    msg_->SerializeToString(&payload);
    pub_.PublishRaw(payload, wireType_);
    ++sent_;
  }
}

void Flood::WaitUntilFlowing(double wait) {
  const std::int64_t end = MonotonicNs() + static_cast<std::int64_t>(wait * 1e9);
  while (started_ == 0 && MonotonicNs() < end && !StopRequested()) SleepFor(0.01);
  if (started_ == 0) {
    Line("FLOOD_NO_CONNECTIONS");
    return;
  }
  Line("FLOOD_START");
  const std::int64_t flowing = started_ + static_cast<std::int64_t>(lead_ * 1e9);
  while (MonotonicNs() < flowing && !StopRequested()) SleepFor(0.01);
}

void Flood::Stop() {
  if (!thread_.joinable()) return;
  stop_ = true;
  thread_.join();
  // ZeroMQ writes from its own I/O thread and the process exits soon after FLOOD_SENT: give
  // the last messages published time to leave, so every message counted is on the wire.
  SleepFor(kFlushSeconds);
  Line("FLOOD_SENT " + std::to_string(sent_.load()));
}

}  // namespace peer
