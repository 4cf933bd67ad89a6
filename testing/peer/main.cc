// Scriptable Ignition Transport 11 peer for the interop tests and the transport benchmark.
// Every mode prints machine-readable lines (READY first once its endpoints exist); see each
// Run* function for its arguments and output.
#include <cstdio>
#include <exception>
#include <map>
#include <string>

#include "args.hh"
#include "messages.hh"
#include "modes.hh"
#include "output.hh"

namespace {

constexpr char kUsage[] =
    "usage: ign_peer MODE ...\n"
    "  pub TOPIC TYPE HZ COUNT [TEXTPROTO] [--bytes N] [--wait S] [--settle S] [--linger S]\n"
    "      [--wire-type WIRETYPE] [--field 'NUMBER TYPE TEXTPROTO']...\n"
    "  pub-many TYPE HZ TEXTPROTO TOPIC... [--wire-type WIRETYPE]\n"
    "  pub-fleet SPECFILE SECONDS   (lines: pub TYPE HZ TOPIC TEXTPROTO | sub TYPE TOPIC)\n"
    "  echo TOPIC TYPE SECONDS [--count N] [--sha | --hex] [--wire-type WIRETYPE]\n"
    "  relay IN OUT TYPE SECONDS\n"
    "  reply SERVICE REQTYPE REPTYPE SECONDS [--fail] [--response TEXTPROTO] [--sha]\n"
    "  call SERVICE REQTYPE REPTYPE TIMEOUT_MS [TEXTPROTO]\n"
    "  bench-pub TOPIC SIZE SECONDS [--hz HZ] [--wait S]\n"
    "  bench-sub TOPIC SECONDS [--count N]\n"
    "  kind-pub TOPIC TYPE FILE SECONDS --stamp PATH [--hz HZ] [--wait S] [--settle S]\n"
    "      [--wire-type WIRETYPE] [--flood TOPIC --flood-type TYPE --flood-file FILE\n"
    "      --flood-stamp PATH [--flood-hz HZ] [--flood-wire-type WIRETYPE] [--flood-lead S]]\n"
    "  kind-sub TOPIC TYPE SECONDS --stamp PATH [--count N] [--wire-type WIRETYPE]\n";

}  // namespace

int main(int argc, char **argv) {
  const std::map<std::string, int (*)(const peer::Args &)> modes = {
      {"pub", peer::RunPub},         {"pub-many", peer::RunPubMany},
      {"pub-fleet", peer::RunPubFleet},
      {"echo", peer::RunEcho},
      {"relay", peer::RunRelay},     {"reply", peer::RunReply},
      {"call", peer::RunCall},       {"bench-pub", peer::RunBenchPub},
      {"bench-sub", peer::RunBenchSub},   {"kind-pub", peer::RunKindPub},
      {"kind-sub", peer::RunKindSub}};
  try {
    const peer::Args args(argc, argv, {"sha", "hex", "fail"});
    const auto mode = modes.find(args.Word(0, "MODE"));
    if (mode == modes.end()) throw peer::UsageError("unknown mode " + args.Word(0, "MODE"));
    peer::InstallStopHandlers();
    return mode->second(args);
  } catch (const peer::UsageError &error) {
    std::fprintf(stderr, "ign_peer: %s\n%s", error.what(), kUsage);
    return 2;
  } catch (const std::exception &error) {
    std::fprintf(stderr, "ign_peer: %s\n", error.what());
    return 1;
  }
}
