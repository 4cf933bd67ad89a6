// ign-transport 11 services are templates over concrete request/response classes, so the
// peer serves and calls a fixed list of types, picked by name at run time.
#pragma once

#include <ignition/msgs/boolean.pb.h>
#include <ignition/msgs/bytes.pb.h>
#include <ignition/msgs/double.pb.h>
#include <ignition/msgs/empty.pb.h>
#include <ignition/msgs/entity.pb.h>
#include <ignition/msgs/entity_factory.pb.h>
#include <ignition/msgs/int32.pb.h>
#include <ignition/msgs/pose.pb.h>
#include <ignition/msgs/stringmsg.pb.h>
#include <ignition/msgs/uint32.pb.h>
#include <ignition/msgs/world_control.pb.h>

#include <string>

#include "args.hh"

namespace peer {

template <class T>
struct TypeTag {
  using Type = T;
};

template <class... Ts>
struct TypeList {};

using ServiceTypes =
    TypeList<ignition::msgs::Boolean, ignition::msgs::Bytes, ignition::msgs::Double,
             ignition::msgs::Empty, ignition::msgs::Entity, ignition::msgs::EntityFactory,
             ignition::msgs::Int32, ignition::msgs::Pose, ignition::msgs::StringMsg,
             ignition::msgs::UInt32, ignition::msgs::WorldControl>;

template <class F, class T, class... Rest>
auto VisitType(const std::string &name, F &&visit, TypeList<T, Rest...>) {
  if (name == T().GetTypeName()) return visit(TypeTag<T>{});
  if constexpr (sizeof...(Rest) > 0) {
    return VisitType(name, visit, TypeList<Rest...>{});
  } else {
    throw UsageError("service type not supported by the peer: " + name);
    return visit(TypeTag<T>{});
  }
}

// Calls `visit(TypeTag<Req>{}, TypeTag<Rep>{})` for the classes named `req` and `rep`.
template <class F>
auto VisitServiceTypes(const std::string &req, const std::string &rep, F &&visit) {
  return VisitType(req, [&](auto reqTag) {
    return VisitType(rep, [&](auto repTag) { return visit(reqTag, repTag); }, ServiceTypes{});
  }, ServiceTypes{});
}

}  // namespace peer
