// The send-time stamp of a typed benchmark message, at a field path such as `header.stamp`,
// `pose.0.header.stamp` (a repeated field's element) or `linear.x`. A path ending at a Time
// message holds sec/nsec; one ending at a double holds seconds.
#pragma once

#include <google/protobuf/message.h>

#include <cstdint>
#include <string>
#include <vector>

namespace peer {

class StampPath {
 public:
  // Throws UsageError when `path` does not lead to a Time message or a double in `prototype`.
  StampPath(const google::protobuf::Message &prototype, const std::string &path);

  void Write(google::protobuf::Message &msg, std::int64_t ns) const;
  // The stamp in `msg`, or -1 when a repeated element on the path is missing.
  std::int64_t Read(const google::protobuf::Message &msg) const;

 private:
  struct Step {
    const google::protobuf::FieldDescriptor *field;
    int index;  // element of a repeated field, -1 for a singular one
  };
  std::vector<Step> steps_;
};

}  // namespace peer
