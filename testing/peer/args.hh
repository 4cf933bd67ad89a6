// Command-line arguments of the peer: positional words plus `--name [value]` options.
#pragma once

#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace peer {

class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Args {
 public:
  // `switches` are the options that take no value; every other `--name` takes one.
  Args(int argc, char **argv, const std::set<std::string> &switches);

  // Positional word `index` (0 = mode); throws UsageError naming `what` when absent.
  const std::string &Word(std::size_t index, const char *what) const;
  std::size_t WordCount() const { return words_.size(); }
  bool Has(const std::string &name) const { return options_.count(name) > 0; }
  // The last value of option `name`, or `fallback` when it was not given.
  std::string Text(const std::string &name, const std::string &fallback) const;
  // Every value of an option that may be repeated, in command-line order.
  std::vector<std::string> All(const std::string &name) const;
  double Number(const std::string &name, double fallback) const;

 private:
  std::vector<std::string> words_;
  std::map<std::string, std::vector<std::string>> options_;
};

double ToNumber(const std::string &text, const char *what);

}  // namespace peer
