#include "args.hh"

namespace peer {

Args::Args(int argc, char **argv, const std::set<std::string> &switches) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg.rfind("--", 0) != 0) {
      words_.push_back(arg);
      continue;
    }
    const std::string name = arg.substr(2);
    if (switches.count(name)) {
      options_[name].push_back("");
    } else if (i + 1 < argc) {
      options_[name].push_back(argv[++i]);
    } else {
      throw UsageError("option --" + name + " needs a value");
    }
  }
}

const std::string &Args::Word(std::size_t index, const char *what) const {
  if (index >= words_.size()) throw UsageError(std::string("missing argument ") + what);
  return words_[index];
}

std::string Args::Text(const std::string &name, const std::string &fallback) const {
  const auto it = options_.find(name);
  return it == options_.end() ? fallback : it->second.back();
}

std::vector<std::string> Args::All(const std::string &name) const {
  const auto it = options_.find(name);
  return it == options_.end() ? std::vector<std::string>{} : it->second;
}

double Args::Number(const std::string &name, double fallback) const {
  const auto it = options_.find(name);
  return it == options_.end() ? fallback : ToNumber(it->second.back(), name.c_str());
}

double ToNumber(const std::string &text, const char *what) {
  try {
    std::size_t used = 0;
    const double value = std::stod(text, &used);
    if (used == text.size()) return value;
  } catch (const std::exception &) {
  }
  throw UsageError(std::string("not a number for ") + what + ": " + text);
}

}  // namespace peer
