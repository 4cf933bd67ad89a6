// The peer's modes; each returns the process exit status. Usage is in main.cc.
#pragma once

#include "args.hh"

namespace peer {

int RunPub(const Args &args);
int RunPubMany(const Args &args);
int RunPubFleet(const Args &args);
int RunEcho(const Args &args);
int RunRelay(const Args &args);
int RunReply(const Args &args);
int RunCall(const Args &args);
int RunBenchPub(const Args &args);
int RunBenchSub(const Args &args);
int RunKindPub(const Args &args);
int RunKindSub(const Args &args);

}  // namespace peer
