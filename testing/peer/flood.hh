// A second stream from the same process as a kind-pub: the camera that floods a simulator's
// process beside its clock. Options of kind-pub:
//   --flood TOPIC --flood-type TYPE --flood-file FILE --flood-stamp PATH [--flood-hz HZ]
//   [--flood-wire-type WIRETYPE] [--flood-lead S]
// The flood has a Node of its own in this process (so it shares the process's ZeroMQ sockets
// and I/O thread with the main publisher, as a simulator's topics do) and its own thread.
#pragma once

#include <google/protobuf/message.h>

#include <ignition/transport/Node.hh>

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>

#include "args.hh"
#include "stamp.hh"

namespace peer {

class Flood {
 public:
  // Advertises the flood topic and starts its thread, which publishes the FILE message (send
  // time at PATH, serialized anew each time) every 1/HZ s, or back to back, once a subscriber
  // is connected.
  explicit Flood(const Args &args);
  ~Flood();
  Flood(const Flood &) = delete;
  Flood &operator=(const Flood &) = delete;

  // Waits (at most `wait` seconds) until the flood has published for --flood-lead seconds;
  // prints FLOOD_START when it publishes, FLOOD_NO_CONNECTIONS when nobody subscribed.
  void WaitUntilFlowing(double wait);
  // Stops the thread, lets the last messages leave, and prints `FLOOD_SENT n`. Idempotent.
  void Stop();

 private:
  void Run();

  ignition::transport::Node node_;
  ignition::transport::Node::Publisher pub_;
  std::unique_ptr<google::protobuf::Message> msg_;
  StampPath stamp_;
  std::string wireType_;
  double hz_;
  double lead_;
  std::atomic<bool> stop_{false};
  std::atomic<std::int64_t> started_{0};
  std::atomic<long> sent_{0};
  std::thread thread_;
};

}  // namespace peer
