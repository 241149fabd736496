#include "capture/rig_text.h"

#include "io/atomic_file.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <stdexcept>

namespace orthoface::capture {
namespace {

[[noreturn]] void fail_at(int line, const std::string& what) {
  throw std::invalid_argument("line " + std::to_string(line) + ": " + what);
}

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }

std::string trim(const std::string& s) {
  size_t b = 0, e = s.size();
  while (b < e && is_blank(s[b])) ++b;
  while (e > b && is_blank(s[e - 1])) --e;
  return s.substr(b, e - b);
}

// What a message may show of file text: at most 40 characters, control / non-ASCII bytes as \xNN.
std::string shown(const std::string& s) {
  std::string out;
  for (size_t i = 0; i < s.size() && i < 40; ++i) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    if (c < 0x20 || c >= 0x7F) {
      char hex[5];
      std::snprintf(hex, sizeof(hex), "\\x%02X", c);
      out += hex;
    } else {
      out += char(c);
    }
  }
  return s.size() > 40 ? "'" + out + "...'" : "'" + out + "'";
}

// Keys are checked for repeats one by one, so a mapping's size is bounded (a rig file's largest
// has a dozen keys).
constexpr size_t kMaxMembers = 1024;

void add_member(RigNode& map, std::string key, RigNode value, int line) {
  if (map.members.size() >= kMaxMembers)
    fail_at(line, "more than " + std::to_string(kMaxMembers) + " keys in one mapping");
  if (map.find(key)) fail_at(line, "key " + shown(key) + " given twice");
  map.members.push_back({std::move(key), std::move(value)});
}

void check_depth(int depth, int line) {
  if (depth > kMaxRigDepth)
    fail_at(line,
            "nested more than " + std::to_string(kMaxRigDepth) + " deep; a rig file nests 4 deep");
}

// ---------------------------------------------------------------- YAML

struct Line {
  int number = 0;    // 1-based
  int indent = 0;    // leading spaces
  std::string body;  // without indentation, comment and trailing blanks
};

// The line without its comment: '#' at the start or after a blank, outside quotes.
std::string strip_comment(const std::string& s, int number) {
  char quote = 0;
  for (size_t i = 0; i < s.size(); ++i) {
    const char c = s[i];
    if (quote) {
      if (c == '\\' && quote == '"' && i + 1 < s.size())
        ++i;
      else if (c == quote)
        quote = 0;
    } else if (c == '"' || c == '\'') {
      // A quote opens a quoted scalar only where one can start (after a blank or , [ { :).
      if (i == 0 || is_blank(s[i - 1]) || s[i - 1] == ',' || s[i - 1] == '[' || s[i - 1] == '{' ||
          s[i - 1] == ':')
        quote = c;
    } else if (c == '#' && (i == 0 || is_blank(s[i - 1]))) {
      return s.substr(0, i);
    }
  }
  if (quote) fail_at(number, "a quoted text is not closed on its line");
  return s;
}

std::vector<Line> yaml_lines(const std::string& text) {
  std::vector<Line> lines;
  bool document_started = false;
  size_t start = 0;
  for (int number = 1; start <= text.size(); ++number) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    std::string raw = text.substr(start, end - start);
    start = end + 1;
    if (!raw.empty() && raw.back() == '\r') raw.pop_back();
    Line l;
    l.number = number;
    while (size_t(l.indent) < raw.size() && raw[size_t(l.indent)] == ' ') ++l.indent;
    if (size_t(l.indent) < raw.size() && raw[size_t(l.indent)] == '\t')
      fail_at(number, "a tab in the indentation (YAML indents with spaces)");
    l.body = trim(strip_comment(raw.substr(size_t(l.indent)), number));
    if (l.body.empty()) continue;
    if (l.indent == 0 && l.body[0] == '%') {
      if (document_started || !lines.empty())
        fail_at(number, "a directive after the document started");
      if (l.body.rfind("%YAML", 0) != 0)
        fail_at(number, "unknown directive " + shown(l.body) + " (only %YAML)");
      continue;
    }
    if (l.indent == 0 && (l.body == "---" || l.body.rfind("--- ", 0) == 0)) {
      if (document_started || !lines.empty())
        fail_at(number, "a second document ('---'); a rig file holds one");
      document_started = true;
      l.body = trim(l.body.substr(3));
      if (l.body.empty()) continue;
    }
    if (l.indent == 0 && l.body == "...") break;  // end of the document
    lines.push_back(std::move(l));
  }
  return lines;
}

class YamlParser {
 public:
  explicit YamlParser(std::vector<Line> lines) : lines_(std::move(lines)) {}

  RigNode parse() {
    if (lines_.empty()) {
      RigNode empty;
      empty.kind = RigNode::Kind::Map;
      return empty;
    }
    if (lines_[0].body[0] == '{') {  // a whole-document flow mapping
      const Line& first = lines_[next_++];
      RigNode node = flow_text(first.body, first.number, 1);
      if (next_ < lines_.size()) fail_at(lines_[next_].number, "text after the document's mapping");
      return node;
    }
    const int indent = lines_[0].indent;
    if (is_item(lines_[0].body))
      fail_at(lines_[0].number, "the document is a sequence, not a mapping");
    RigNode node = block_map(indent, 1);
    if (next_ < lines_.size())
      fail_at(lines_[next_].number, "indented less than the document's first key");
    return node;
  }

 private:
  static bool is_item(const std::string& body) {
    return body[0] == '-' && (body.size() == 1 || body[1] == ' ');
  }

  // The key of `key: value` and the position of the value; fails when there is no ': '.
  static std::string split_key(const std::string& body, int number, std::string& rest) {
    size_t colon = std::string::npos;
    std::string key;
    if (body[0] == '"' || body[0] == '\'') {
      size_t pos = 0;
      key = quoted(body, pos, number);
      if (pos < body.size() && body[pos] == ':') colon = pos;
    } else {
      for (size_t i = 0; i < body.size(); ++i)
        if (body[i] == ':' && (i + 1 == body.size() || body[i + 1] == ' ')) {
          colon = i;
          break;
        }
      if (colon != std::string::npos) key = trim(body.substr(0, colon));
    }
    if (colon == std::string::npos) fail_at(number, "expected 'key: value', got " + shown(body));
    if (key.empty()) fail_at(number, "a key is empty");
    rest = trim(body.substr(colon + 1));
    return key;
  }

  RigNode block_map(int indent, int depth) {
    check_depth(depth, lines_[next_].number);
    RigNode map;
    map.kind = RigNode::Kind::Map;
    map.line = lines_[next_].number;
    while (next_ < lines_.size() && lines_[next_].indent == indent) {
      const Line& l = lines_[next_];
      if (is_item(l.body)) fail_at(l.number, "a sequence item among the keys of a mapping");
      std::string rest;
      std::string key = split_key(l.body, l.number, rest);
      const int number = l.number;
      ++next_;
      add_member(map, std::move(key), value(rest, indent, depth + 1, number), number);
    }
    if (next_ < lines_.size() && lines_[next_].indent > indent)
      fail_at(lines_[next_].number, "indented more than the key before it");
    return map;
  }

  RigNode block_seq(int indent, int depth) {
    check_depth(depth, lines_[next_].number);
    RigNode seq;
    seq.kind = RigNode::Kind::Seq;
    seq.line = lines_[next_].number;
    while (next_ < lines_.size() && lines_[next_].indent == indent && is_item(lines_[next_].body)) {
      const int number = lines_[next_].number;
      const std::string rest = trim(lines_[next_].body.substr(1));
      ++next_;
      seq.items.push_back(value(rest, indent, depth + 1, number, /*after_key=*/false));
    }
    if (next_ < lines_.size() && lines_[next_].indent > indent)
      fail_at(lines_[next_].number, "indented more than the item before it");
    return seq;
  }

  // The value after `key:` or `-` on line `number` (`rest`, maybe empty: then the indented
  // lines below, or an empty scalar).
  RigNode value(std::string rest, int indent, int depth, int number, bool after_key = true) {
    check_depth(depth, number);
    std::string tag;
    if (!rest.empty() && rest[0] == '!') {
      const size_t start = rest.compare(0, 2, "!!") == 0 ? 2 : 1;
      const size_t end = std::max(start, std::min(rest.find(' '), rest.size()));
      tag = rest.substr(start, end - start);
      rest = trim(rest.substr(end));
      if (tag.empty()) fail_at(number, "an empty tag");
    }
    RigNode node;
    if (rest.empty()) {
      if (next_ < lines_.size() && lines_[next_].indent > indent)
        node = is_item(lines_[next_].body) ? block_seq(lines_[next_].indent, depth)
                                           : block_map(lines_[next_].indent, depth);
      else if (after_key && next_ < lines_.size() && lines_[next_].indent == indent &&
               is_item(lines_[next_].body))
        node = block_seq(indent, depth);  // `key:` then `- item` at the key's indentation
      else
        node.line = number;  // an empty scalar
    } else if (rest[0] == '[' || rest[0] == '{') {
      node = flow_text(rest, number, depth);
    } else {
      size_t pos = 0;
      node = scalar_token(rest, pos, number, /*flow=*/false);
      if (pos != rest.size())
        fail_at(number, "unexpected text " + shown(rest.substr(pos)) + " after a value");
    }
    if (node.line == 0) node.line = number;
    node.tag = tag;
    return node;
  }

  // A flow collection starting in `rest` and continued on the following lines until its
  // brackets close. Each line is scanned once, however many the collection spans.
  RigNode flow_text(std::string text, int number, int depth) {
    BracketScan scan;
    scan.feed(text);
    while (!scan.closed) {
      if (next_ >= lines_.size()) fail_at(number, "a '[' or '{' is never closed");
      const std::string more = " " + lines_[next_].body;
      scan.feed(more);
      text += more;
      ++next_;
    }
    size_t pos = 0;
    RigNode node = flow(text, pos, number, depth);
    skip_blanks(text, pos);
    if (pos != text.size())
      fail_at(number, "unexpected text " + shown(text.substr(pos)) + " after a value");
    return node;
  }

  // Where the brackets of a flow collection fed in pieces close (outside quotes; a quote opens
  // only where a quoted value can start, as in strip_comment).
  struct BracketScan {
    int depth = 0;
    char quote = 0, prev = ' ';
    bool escaped = false, closed = false;
    void feed(const std::string& s) {
      for (const char c : s) {
        if (closed) return;
        if (quote) {
          if (escaped)
            escaped = false;
          else if (c == '\\' && quote == '"')
            escaped = true;
          else if (c == quote)
            quote = 0;
        } else if ((c == '"' || c == '\'') &&
                   (is_blank(prev) || prev == ',' || prev == '[' || prev == '{' || prev == ':')) {
          quote = c;
        } else if (c == '[' || c == '{') {
          ++depth;
        } else if ((c == ']' || c == '}') && --depth <= 0) {
          closed = true;
        }
        prev = c;
      }
    }
  };

  static void skip_blanks(const std::string& s, size_t& pos) {
    while (pos < s.size() && is_blank(s[pos])) ++pos;
  }

  RigNode flow(const std::string& s, size_t& pos, int number, int depth) {
    check_depth(depth, number);
    skip_blanks(s, pos);
    RigNode node;
    node.line = number;
    const char open = s[pos++];
    const char close = open == '[' ? ']' : '}';
    node.kind = open == '[' ? RigNode::Kind::Seq : RigNode::Kind::Map;
    for (;;) {
      skip_blanks(s, pos);
      if (pos >= s.size()) fail_at(number, std::string("a '") + open + "' is never closed");
      if (s[pos] == close) {
        ++pos;
        return node;
      }
      if (node.is_seq()) {
        node.items.push_back(flow_item(s, pos, number, depth + 1));
      } else {
        RigNode key = scalar_token(s, pos, number, /*flow=*/true, /*key=*/true);
        skip_blanks(s, pos);
        if (pos >= s.size() || s[pos] != ':')
          fail_at(number, "expected ':' after the key " + shown(key.text));
        ++pos;
        add_member(node, key.text, flow_item(s, pos, number, depth + 1), number);
      }
      skip_blanks(s, pos);
      if (pos < s.size() && s[pos] == ',') {
        ++pos;
      } else if (pos >= s.size() || s[pos] != close) {
        fail_at(number,
                std::string("expected ',' or '") + close + "', got " + shown(s.substr(pos)));
      }
    }
  }

  RigNode flow_item(const std::string& s, size_t& pos, int number, int depth) {
    skip_blanks(s, pos);
    std::string tag;
    if (pos < s.size() && s[pos] == '!') {
      const size_t start = pos + (s.compare(pos, 2, "!!") == 0 ? 2 : 1);
      size_t end = start;
      while (end < s.size() && !is_blank(s[end]) && s[end] != ',' && s[end] != ']' && s[end] != '}')
        ++end;
      tag = s.substr(start, end - start);
      if (tag.empty()) fail_at(number, "an empty tag");
      pos = end;
      skip_blanks(s, pos);
    }
    RigNode node = pos < s.size() && (s[pos] == '[' || s[pos] == '{')
                       ? flow(s, pos, number, depth)
                       : scalar_token(s, pos, number, /*flow=*/true);
    node.tag = tag;
    return node;
  }

  // A quoted text starting at s[pos]; pos ends past the closing quote.
  static std::string quoted(const std::string& s, size_t& pos, int number) {
    const char q = s[pos++];
    std::string out;
    for (;;) {
      if (pos >= s.size()) fail_at(number, "a quoted text is not closed");
      const char c = s[pos++];
      if (c == q) {
        if (q == '\'' && pos < s.size() && s[pos] == '\'') {  // '' is a quote
          out += '\'';
          ++pos;
          continue;
        }
        return out;
      }
      if (c == '\\' && q == '"') {
        if (pos >= s.size()) fail_at(number, "a quoted text is not closed");
        const char e = s[pos++];
        switch (e) {
          case '\\':
            out += '\\';
            break;
          case '"':
            out += '"';
            break;
          case '/':
            out += '/';
            break;
          case 'n':
            out += '\n';
            break;
          case 't':
            out += '\t';
            break;
          case 'r':
            out += '\r';
            break;
          default:
            fail_at(number, std::string("unknown escape \\") + shown(std::string(1, e)));
        }
        continue;
      }
      out += c;
    }
  }

  // A scalar at s[pos]: quoted, or plain up to the end (block) or to , ] } (flow; and : for a
  // flow mapping's key).
  static RigNode scalar_token(const std::string& s, size_t& pos, int number, bool flow,
                              bool key = false) {
    RigNode node;
    node.line = number;
    if (pos < s.size() && (s[pos] == '"' || s[pos] == '\'')) {
      node.text = quoted(s, pos, number);
      node.quoted = true;
      skip_blanks(s, pos);
      return node;
    }
    const size_t start = pos;
    while (pos < s.size()) {
      const char c = s[pos];
      if (flow && (c == ',' || c == ']' || c == '}' || (key && c == ':'))) break;
      if (c == '[' || c == '{' || c == ']' || c == '}')
        fail_at(number, "a bracket inside a plain value: " + shown(s.substr(start)));
      if (c == ':' && (pos + 1 == s.size() || s[pos + 1] == ' ') && !key)
        fail_at(number,
                "a mapping inside a value (" + shown(s.substr(start)) + "); one key per line");
      ++pos;
    }
    node.text = trim(s.substr(start, pos - start));
    if (flow && node.text.empty()) fail_at(number, "an empty value in a '[ ]' or '{ }'");
    return node;
  }

  std::vector<Line> lines_;
  size_t next_ = 0;
};

// ---------------------------------------------------------------- XML

class XmlParser {
 public:
  explicit XmlParser(const std::string& text) : s_(text) {}

  RigNode parse() {
    skip_misc();
    if (s_.compare(pos_, 5, "<?xml") == 0) {
      const size_t end = s_.find("?>", pos_);
      if (end == std::string::npos) fail("the <?xml declaration is never closed");
      pos_ = end + 2;
    }
    skip_misc();
    if (pos_ >= s_.size() || s_[pos_] != '<') fail("expected the root element");
    std::string root_name;
    RigNode root = element(1, root_name);
    if (root.is_scalar() && trim(root.text).empty()) root.kind = RigNode::Kind::Map;
    if (!root.is_map()) fail("the root element <" + root_name + "> does not hold named elements");
    skip_misc();
    if (pos_ != s_.size()) fail("text after the root element");
    return root;
  }

 private:
  [[noreturn]] void fail(const std::string& what) const { fail_at(line_here(), what); }

  // The line of pos_, counted on from the last call (pos_ only moves forward).
  int line_here() const {
    for (; counted_ < pos_ && counted_ < s_.size(); ++counted_) line_ += s_[counted_] == '\n';
    return line_;
  }

  void skip_blanks() {
    while (pos_ < s_.size() && is_blank(s_[pos_])) ++pos_;
  }

  // Blanks and comments.
  void skip_misc() {
    for (;;) {
      skip_blanks();
      if (s_.compare(pos_, 4, "<!--") != 0) return;
      const size_t end = s_.find("-->", pos_ + 4);
      if (end == std::string::npos) fail("a comment is never closed");
      pos_ = end + 3;
    }
  }

  static bool name_char(char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.' ||
           c == ':';
  }

  std::string name() {
    const size_t start = pos_;
    while (pos_ < s_.size() && name_char(s_[pos_])) ++pos_;
    if (pos_ == start) fail("expected an element or attribute name");
    return s_.substr(start, pos_ - start);
  }

  std::string decoded(const std::string& raw) const {
    std::string out;
    for (size_t i = 0; i < raw.size(); ++i) {
      if (raw[i] != '&') {
        out += raw[i];
        continue;
      }
      static const std::pair<const char*, char> kEntities[] = {
          {"&lt;", '<'}, {"&gt;", '>'}, {"&amp;", '&'}, {"&quot;", '"'}, {"&apos;", '\''}};
      bool known = false;
      for (const auto& [entity, c] : kEntities)
        if (raw.compare(i, std::char_traits<char>::length(entity), entity) == 0) {
          out += c;
          i += std::char_traits<char>::length(entity) - 1;
          known = true;
          break;
        }
      if (!known) fail("an unknown entity " + shown(raw.substr(i, 8)));
    }
    return out;
  }

  // The element at pos_ ('<'); `element_name` receives its name.
  RigNode element(int depth, std::string& element_name) {
    check_depth(depth, line_here());
    RigNode node;
    node.line = line_here();
    ++pos_;  // '<'
    element_name = name();
    for (;;) {  // attributes
      skip_blanks();
      if (pos_ >= s_.size()) fail("the tag <" + element_name + " is never closed");
      if (s_.compare(pos_, 2, "/>") == 0) {
        pos_ += 2;
        return node;  // an empty scalar
      }
      if (s_[pos_] == '>') {
        ++pos_;
        break;
      }
      const std::string attr = name();
      skip_blanks();
      if (pos_ >= s_.size() || s_[pos_] != '=') fail("expected '=' after the attribute " + attr);
      ++pos_;
      skip_blanks();
      if (pos_ >= s_.size() || (s_[pos_] != '"' && s_[pos_] != '\''))
        fail("an attribute value must be quoted");
      const char q = s_[pos_++];
      const size_t end = s_.find(q, pos_);
      if (end == std::string::npos) fail("an attribute value is never closed");
      const std::string value = decoded(s_.substr(pos_, end - pos_));
      pos_ = end + 1;
      if (attr == "type_id") node.tag = value;
    }
    std::string text;
    std::vector<std::pair<std::string, RigNode>> children;
    for (;;) {
      const size_t lt = s_.find('<', pos_);
      if (lt == std::string::npos) fail("<" + element_name + "> is never closed");
      text += s_.substr(pos_, lt - pos_);
      pos_ = lt;
      if (s_.compare(pos_, 4, "<!--") == 0) {
        skip_misc();
        continue;
      }
      if (s_.compare(pos_, 2, "</") == 0) {
        pos_ += 2;
        const std::string closing = name();
        skip_blanks();
        if (closing != element_name || pos_ >= s_.size() || s_[pos_] != '>')
          fail("<" + element_name + "> is closed by </" + closing + ">");
        ++pos_;
        break;
      }
      if (s_.compare(pos_, 2, "<!") == 0 || s_.compare(pos_, 2, "<?") == 0)
        fail("CDATA, DOCTYPE and processing instructions are not part of a rig file");
      std::string child_name;
      RigNode child = element(depth + 1, child_name);
      children.emplace_back(std::move(child_name), std::move(child));
    }
    if (children.empty()) return text_node(std::move(node), decoded(text));
    if (!trim(text).empty()) fail("<" + element_name + "> mixes text and elements");
    const bool seq = children[0].first == "_";
    node.kind = seq ? RigNode::Kind::Seq : RigNode::Kind::Map;
    for (auto& [child_name, child] : children) {
      if ((child_name == "_") != seq)
        fail("<" + element_name + "> mixes sequence items <_> and named elements");
      if (seq)
        node.items.push_back(std::move(child));
      else {
        const int line = child.line;
        add_member(node, child_name, std::move(child), line);
      }
    }
    return node;
  }

  // An element's text: one token (or a "quoted" text) a scalar, several tokens a sequence.
  static RigNode text_node(RigNode node, const std::string& raw) {
    const std::string text = trim(raw);
    if (text.size() >= 2 && text.front() == '"' && text.back() == '"') {
      node.text = text.substr(1, text.size() - 2);
      node.quoted = true;
      return node;
    }
    std::vector<std::string> tokens;
    for (size_t i = 0; i < text.size();) {
      while (i < text.size() && is_blank(text[i])) ++i;
      const size_t start = i;
      while (i < text.size() && !is_blank(text[i])) ++i;
      if (i > start) tokens.push_back(text.substr(start, i - start));
    }
    if (tokens.size() <= 1) {
      node.text = tokens.empty() ? "" : tokens[0];
      return node;
    }
    node.kind = RigNode::Kind::Seq;
    for (std::string& t : tokens) {
      RigNode item;
      item.line = node.line;
      item.text = std::move(t);
      node.items.push_back(std::move(item));
    }
    return node;
  }

  const std::string& s_;
  size_t pos_ = 0;
  mutable size_t counted_ = 0;  // line_here's progress
  mutable int line_ = 1;
};

}  // namespace

const RigNode* RigNode::find(const std::string& key) const {
  if (kind != Kind::Map) return nullptr;
  for (const auto& [name, value] : members)
    if (name == key) return &value;
  return nullptr;
}

std::optional<long long> RigNode::as_int() const {
  if (kind != Kind::Scalar || quoted || text.empty()) return std::nullopt;
  const char* begin = text.data() + (text[0] == '+' ? 1 : 0);
  const char* end = text.data() + text.size();
  long long v = 0;
  const auto [ptr, ec] = std::from_chars(begin, end, v);
  if (ec != std::errc() || ptr != end || begin == end) return std::nullopt;
  if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max())
    return std::nullopt;
  return v;
}

std::optional<double> RigNode::as_number() const {
  if (kind != Kind::Scalar || quoted || text.empty()) return std::nullopt;
  std::string t = text;
  double sign = 1;
  if (t[0] == '+' || t[0] == '-') {
    sign = t[0] == '-' ? -1 : 1;
    t.erase(0, 1);
  }
  if (t == ".nan" || t == ".NaN" || t == ".NAN") return std::numeric_limits<double>::quiet_NaN();
  if (t == ".inf" || t == ".Inf" || t == ".INF")
    return sign * std::numeric_limits<double>::infinity();
  if (t.empty() || !(std::isdigit(static_cast<unsigned char>(t[0])) || t[0] == '.'))
    return std::nullopt;
  double v = 0;
  const auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  if (ptr != t.data() + t.size()) return std::nullopt;
  if (ec == std::errc::result_out_of_range) return sign * std::numeric_limits<double>::infinity();
  if (ec != std::errc()) return std::nullopt;
  return sign * v;
}

RigNode parse_rig_text(const std::string& text) {
  if (text.size() > kMaxRigBytes)
    throw std::invalid_argument("over 1 MiB; a rig file is a few kB of text");
  int line = 1;
  for (size_t i = 0; i < text.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c == '\n') ++line;
    if (c < 0x20 && c != '\t' && c != '\n' && c != '\r') {
      char what[80];
      std::snprintf(what, sizeof(what), "byte 0x%02X at offset %zu: not a text file", c, i);
      fail_at(line, what);
    }
  }
  size_t first = 0;
  while (first < text.size() && is_blank(text[first])) ++first;
  if (first < text.size() && text[first] == '<') return XmlParser(text).parse();
  return YamlParser(yaml_lines(text)).parse();
}

RigNode read_rig_text(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw std::runtime_error("rig file " + path + ": no such file");
  if (std::filesystem::file_size(path, ec) > kMaxRigBytes)
    throw std::runtime_error("rig file " + path + ": over 1 MiB; a rig file is a few kB of text");
  std::ifstream in(path, std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!in.good() && !in.eof()) throw std::runtime_error("rig file " + path + ": cannot be read");
  try {
    return parse_rig_text(text);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error("rig file " + path + ": " + e.what());
  }
}

void write_rig_text(const std::string& path, const std::function<void(cv::FileStorage&)>& fill) {
  const bool xml =
      path.size() >= 4 && std::equal(path.end() - 4, path.end(), ".xml", [](char a, char b) {
        return std::tolower(static_cast<unsigned char>(a)) == b;
      });
  std::string text;
  try {
    cv::FileStorage fs(xml ? "rig.xml" : "rig.yaml",
                       cv::FileStorage::WRITE | cv::FileStorage::MEMORY |
                           (xml ? cv::FileStorage::FORMAT_XML : cv::FileStorage::FORMAT_YAML));
    fill(fs);
    text = fs.releaseAndGetString();
  } catch (const cv::Exception& e) {
    throw std::runtime_error("cannot write rig file " + path + ": " + e.err);
  }
  io::write_text_atomically(path, text);
}

cv::Mat matrix_from_node(const RigNode& n) {
  if (!n.is_map())
    throw std::invalid_argument("is not a matrix (!!opencv-matrix with rows, cols, dt, data)");
  if (!n.tag.empty() && n.tag != "opencv-matrix")
    throw std::invalid_argument("is tagged " + shown(n.tag) + ", not opencv-matrix");
  const RigNode *rows = n.find("rows"), *cols = n.find("cols"), *dt = n.find("dt"),
                *data = n.find("data");
  if (!rows || !cols || !data) throw std::invalid_argument("needs rows, cols and data");
  const std::optional<long long> r = rows->as_int(), c = cols->as_int();
  if (!r || !c) throw std::invalid_argument("needs whole numbers for rows and cols");
  if (*r < 1 || *r > 16 || *c < 1 || *c > 16)
    throw std::invalid_argument("is " + std::to_string(*r) + " x " + std::to_string(*c) +
                                "; a rig matrix has 1..16 rows and columns");
  if (dt) {
    const std::string& t = dt->text;
    if (!dt->is_scalar() || t.empty() || std::string("ucwsifd").find(t.back()) == std::string::npos)
      throw std::invalid_argument("has dt " + shown(t) + "; expected one of u c w s i f d");
    if (t.size() > 1 && t.substr(0, t.size() - 1) != "1")
      throw std::invalid_argument("must have one channel (dt " + shown(t) + ")");
  }
  std::vector<const RigNode*> values;
  if (data->is_seq())
    for (const RigNode& v : data->items) values.push_back(&v);
  else if (data->is_scalar() && !data->text.empty())
    values.push_back(data);
  if (values.size() != size_t(*r * *c))
    throw std::invalid_argument("needs " + std::to_string(*r * *c) +
                                " data values (rows x cols), has " + std::to_string(values.size()));
  cv::Mat m(int(*r), int(*c), CV_64F);
  for (size_t i = 0; i < values.size(); ++i) {
    const std::optional<double> v = values[i]->as_number();
    if (!v)
      throw std::invalid_argument("data value " + std::to_string(i + 1) + " " +
                                  shown(values[i]->text) + " is not a number");
    m.at<double>(int(i)) = *v;
  }
  return m;
}

}  // namespace orthoface::capture
