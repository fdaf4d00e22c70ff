// The pre-parse scan of JSON text (json_limits.h): one pass over the bytes with an explicit,
// bounded stack, so a document nested 200,000 levels deep fails here instead of in a
// recursive copy or destructor later.
#include "ipm_road_mapper/core/io/json_limits.h"

#include <vector>

namespace ipm_road_mapper {
namespace json_limits {
namespace {

// Path components are cut to this many characters in messages.
constexpr std::size_t kMaxKeyChars = 32;
// A message shows at most this many characters of the path.
constexpr std::size_t kMaxPathChars = 120;

// One open array or object of the scan.
struct Container {
  bool is_object = false;
  bool empty = true;          // no element seen yet
  bool expecting_key = true;  // objects: the next string is a member name
  std::size_t index = 0;      // arrays: index of the current element
  std::string key;            // objects: name of the current member
};

// The JSON path through the outermost `levels` open containers: with all of them the path
// of the innermost's current element ("lanes[3].control_points[7]"), with one fewer the
// path of the innermost container itself ("lanes[3].control_points").
std::string PathOf(const std::vector<Container>& stack, std::size_t levels) {
  std::string path;
  for (std::size_t k = 0; k < levels && k < stack.size(); ++k) {
    const Container& c = stack[k];
    if (c.empty) break;
    if (c.is_object) {
      path += (path.empty() ? "" : ".") + c.key;
    } else {
      path += "[" + std::to_string(c.index) + "]";
    }
    if (path.size() > kMaxPathChars) return path.substr(0, kMaxPathChars) + "...";
  }
  return path.empty() ? "<root>" : path;
}

std::string Prefixed(const std::vector<Container>& stack, std::size_t levels,
                     const std::string& what) {
  return PathOf(stack, levels) + ": " + what;
}

}  // namespace

std::string ScanJsonText(const std::string& text) {
  std::vector<Container> stack;
  stack.reserve(kMaxDepth + 1);
  std::size_t values = 1;
  bool in_string = false, in_key = false, escaped = false;
  // Marks the start of an element of the innermost container.
  auto start_element = [&]() -> std::string {
    if (stack.empty() || !stack.back().empty) return "";
    stack.back().empty = false;
    if (++values > kMaxValues) {
      return "more than " + std::to_string(kMaxValues) + " JSON values in the document";
    }
    return "";
  };
  for (const char ch : text) {
    if (in_string) {
      if (escaped) {
        escaped = false;
      } else if (ch == '\\') {
        escaped = true;
      } else if (ch == '"') {
        in_string = in_key = false;
      }
      if (in_key && stack.back().key.size() < kMaxKeyChars) stack.back().key += ch;
      continue;
    }
    if (ch == ' ' || ch == '\n' || ch == '\r' || ch == '\t') continue;
    if (ch == ',') {
      if (stack.empty()) continue;  // a syntax error: the parser reports it
      Container& top = stack.back();
      if (++top.index >= kMaxContainerElements) {
        return Prefixed(stack, stack.size() - 1,
                        "more than " + std::to_string(kMaxContainerElements) +
                            " elements in one array or object");
      }
      if (++values > kMaxValues) {
        return "more than " + std::to_string(kMaxValues) + " JSON values in the document";
      }
      if (top.is_object) {
        top.expecting_key = true;
        top.key.clear();
      }
      continue;
    }
    if (ch == ':') {
      if (!stack.empty()) stack.back().expecting_key = false;
      continue;
    }
    if (ch == ']' || ch == '}') {
      if (!stack.empty()) stack.pop_back();
      continue;
    }
    const std::string problem = start_element();
    if (!problem.empty()) return problem;
    if (ch == '"') {
      in_string = true;
      in_key = !stack.empty() && stack.back().is_object && stack.back().expecting_key;
      if (in_key) stack.back().key.clear();
    } else if (ch == '[' || ch == '{') {
      if (static_cast<int>(stack.size()) >= kMaxDepth) {
        return Prefixed(stack, stack.size(),
                        "nesting deeper than " + std::to_string(kMaxDepth) + " levels");
      }
      Container opened;
      opened.is_object = ch == '{';
      stack.push_back(opened);
    }
  }
  return "";
}

}  // namespace json_limits
}  // namespace ipm_road_mapper
