#include "stamp.hh"

#include <google/protobuf/descriptor.h>

#include <cmath>
#include <sstream>

#include "args.hh"

namespace peer {
namespace {

using google::protobuf::FieldDescriptor;
using google::protobuf::Message;

constexpr std::int64_t kNsPerS = 1000000000;

bool IsTime(const FieldDescriptor *field) {
  return field->type() == FieldDescriptor::TYPE_MESSAGE &&
         field->message_type()->FindFieldByName("sec") &&
         field->message_type()->FindFieldByName("nsec");
}

}  // namespace

StampPath::StampPath(const Message &prototype, const std::string &path) {
  const auto *descriptor = prototype.GetDescriptor();
  std::istringstream words(path);
  std::string word;
  while (std::getline(words, word, '.')) {
    if (!descriptor) throw UsageError("stamp path " + path + " goes past a scalar field");
    if (!steps_.empty() && steps_.back().field->is_repeated() && steps_.back().index < 0) {
      steps_.back().index = static_cast<int>(ToNumber(word, "stamp path index"));
      continue;
    }
    const auto *field = descriptor->FindFieldByName(word);
    if (!field) throw UsageError("stamp path " + path + ": no field " + word);
    steps_.push_back({field, -1});
    descriptor = field->type() == FieldDescriptor::TYPE_MESSAGE ? field->message_type() : nullptr;
  }
  if (steps_.empty() || (steps_.back().field->is_repeated())) {
    throw UsageError("stamp path " + path + " must end at a singular field");
  }
  const auto *last = steps_.back().field;
  if (!IsTime(last) && last->type() != FieldDescriptor::TYPE_DOUBLE) {
    throw UsageError("stamp path " + path + " must end at a Time message or a double");
  }
}

void StampPath::Write(Message &msg, std::int64_t ns) const {
  Message *at = &msg;
  for (std::size_t i = 0; i + 1 < steps_.size(); ++i) {
    const auto &step = steps_[i];
    const auto *reflection = at->GetReflection();
    if (step.index < 0) {
      at = reflection->MutableMessage(at, step.field);
      continue;
    }
    while (reflection->FieldSize(*at, step.field) <= step.index) reflection->AddMessage(at, step.field);
    at = reflection->MutableRepeatedMessage(at, step.field, step.index);
  }
  const auto *last = steps_.back().field;
  if (last->type() == FieldDescriptor::TYPE_DOUBLE) {
    at->GetReflection()->SetDouble(at, last, double(ns) / double(kNsPerS));
    return;
  }
  Message *time = at->GetReflection()->MutableMessage(at, last);
  const auto *fields = time->GetDescriptor();
  time->GetReflection()->SetInt64(time, fields->FindFieldByName("sec"), ns / kNsPerS);
  time->GetReflection()->SetInt32(time, fields->FindFieldByName("nsec"),
                                  static_cast<std::int32_t>(ns % kNsPerS));
}

std::int64_t StampPath::Read(const Message &msg) const {
  const Message *at = &msg;
  for (std::size_t i = 0; i + 1 < steps_.size(); ++i) {
    const auto &step = steps_[i];
    const auto *reflection = at->GetReflection();
    if (step.index < 0) {
      at = &reflection->GetMessage(*at, step.field);
    } else if (reflection->FieldSize(*at, step.field) > step.index) {
      at = &reflection->GetRepeatedMessage(*at, step.field, step.index);
    } else {
      return -1;
    }
  }
  const auto *last = steps_.back().field;
  if (last->type() == FieldDescriptor::TYPE_DOUBLE) {
    return std::llround(at->GetReflection()->GetDouble(*at, last) * double(kNsPerS));
  }
  const Message &time = at->GetReflection()->GetMessage(*at, last);
  const auto *fields = time.GetDescriptor();
  return time.GetReflection()->GetInt64(time, fields->FindFieldByName("sec")) * kNsPerS +
         time.GetReflection()->GetInt32(time, fields->FindFieldByName("nsec"));
}

}  // namespace peer
