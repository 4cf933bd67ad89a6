// reply and call: the service side of the peer.
#include <google/protobuf/text_format.h>
#include <ignition/transport/Node.hh>

#include <atomic>
#include <string>

#include "messages.hh"
#include "modes.hh"
#include "output.hh"
#include "service_types.hh"

namespace peer {

// reply SERVICE REQTYPE REPTYPE SECONDS [--fail] [--response TEXTPROTO] [--sha]
// Answers every request: with --response if given, else the request itself when the types
// match, else `data: true` for a Boolean response, else an empty response. --fail answers
// with result false. Prints `REQUEST <type> <text|sha256=..>` per call, then `SERVED n`.
int RunReply(const Args &args) {
  const std::string service = args.Word(1, "SERVICE");
  const std::string reqType = args.Word(2, "REQTYPE");
  const std::string repType = args.Word(3, "REPTYPE");
  const double seconds = ToNumber(args.Word(4, "SECONDS"), "SECONDS");
  const bool fail = args.Has("fail");
  const bool sha = args.Has("sha");
  const std::string responseText = args.Text("response", "");
  std::atomic<long> served{0};
  ignition::transport::Node node;

  const bool advertised = VisitServiceTypes(reqType, repType, [&](auto reqTag, auto repTag) {
    using Req = typename decltype(reqTag)::Type;
    using Rep = typename decltype(repTag)::Type;
    Rep canned;
    if (!responseText.empty() &&
        !google::protobuf::TextFormat::ParseFromString(responseText, &canned)) {
      throw UsageError("--response does not parse as " + repType);
    }
    std::function<bool(const Req &, Rep &)> handler = [&, canned](const Req &req, Rep &rep) {
      std::string bytes;
      req.SerializeToString(&bytes);
      Line("REQUEST " + reqType + " " + (sha ? Digest(bytes.data(), bytes.size()) : OneLine(req)));
      ++served;
      if (fail) return false;
      if (!responseText.empty()) {
        rep.CopyFrom(canned);
      } else if (rep.GetDescriptor() == req.GetDescriptor()) {
        rep.CopyFrom(req);
      } else if (auto *data = rep.GetDescriptor()->FindFieldByName("data");
                 data && data->type() == google::protobuf::FieldDescriptor::TYPE_BOOL) {
        rep.GetReflection()->SetBool(&rep, data, true);
      }
      return true;
    };
    return node.Advertise(service, handler);
  });
  if (!advertised) {
    Line("ERROR advertise failed for " + service);
    return 1;
  }
  Line("READY");
  RunFor(seconds);
  Line("SERVED " + std::to_string(served.load()));
  return 0;
}

// call SERVICE REQTYPE REPTYPE TIMEOUT_MS TEXTPROTO
// Prints `RESPONSE <type> <text>`, `FAILED` or `TIMEOUT`; exit status 0, 3, 4 respectively.
int RunCall(const Args &args) {
  const std::string service = args.Word(1, "SERVICE");
  const std::string reqType = args.Word(2, "REQTYPE");
  const std::string repType = args.Word(3, "REPTYPE");
  const auto timeoutMs = static_cast<unsigned int>(ToNumber(args.Word(4, "TIMEOUT_MS"), "TIMEOUT_MS"));
  const std::string text = args.WordCount() > 5 ? args.Word(5, "TEXTPROTO") : "";
  ignition::transport::Node node;

  return VisitServiceTypes(reqType, repType, [&](auto reqTag, auto repTag) {
    using Req = typename decltype(reqTag)::Type;
    using Rep = typename decltype(repTag)::Type;
    Req req;
    if (!google::protobuf::TextFormat::ParseFromString(text, &req)) {
      throw UsageError("request does not parse as " + reqType + ": " + text);
    }
    Rep rep;
    bool result = false;
    if (!node.Request(service, req, timeoutMs, rep, result)) {
      Line("TIMEOUT");
      return 4;
    }
    if (!result) {
      Line("FAILED");
      return 3;
    }
    Line("RESPONSE " + repType + " " + OneLine(rep));
    return 0;
  });
}

}  // namespace peer
