// OBJ/MTL line checks with file:line errors, and the text tinyobjloader parses.
#include "scene/obj_lint.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iomanip>
#include <map>
#include <sstream>

#include "base/error.h"
#include "scene/scene.h"

namespace fh {
namespace {

constexpr size_t kMaxDigits = 100;       // digits before the exponent (numberSyntax)
constexpr long kMaxExponent = 300;       // |exponent| (numberSyntax)
constexpr long kMaxIndex = 2147483647L;  // tinyobjloader reads indices with atoi (an int)
constexpr size_t kMaxKindWarnings = 8;   // ignored-statement kinds named one by one

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return s;
}

bool isDigit(char c) { return c >= '0' && c <= '9'; }

// True when `text` holds `prefix` at `at`.
bool hasAt(const std::string& text, size_t at, const char* prefix) {
  const size_t n = std::strlen(prefix);
  return at <= text.size() && text.size() - at >= n && text.compare(at, n, prefix) == 0;
}

// A UTF-8 byte order mark: editors on Windows write one. Skipped, or the first statement
// (often `mtllib`) would read as an unknown word.
size_t bomLength(const std::string& text) { return hasAt(text, 0, "\xEF\xBB\xBF") ? 3 : 0; }

// A control character the line reader cannot accept (see requirePlainText).
bool isControl(unsigned char c) { return (c < 0x20 && c != '\n' && c != '\t' && c != '\r') || c == 0x7f; }

// The lint must read the lines and tokens the loader (tinyobjloader) reads, or it checks
// other statements than those loaded. The two agree on lines that end in \n or \r\n and on
// tokens separated by spaces and tabs; they split differently at a lone \r (a line end to
// tinyobjloader), at \v, \f and NUL. Text holding those is refused, naming the line.
void requirePlainText(const std::string& text, const std::string& name, size_t start) {
  int line = 1;
  for (size_t i = start; i < text.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c == '\n') ++line;
    const bool crlf = c == '\r' && i + 1 < text.size() && text[i + 1] == '\n';
    if (isControl(c) || (c == '\r' && !crlf)) {
      std::ostringstream msg;
      msg << name << ":" << line << ": ";
      if (c == '\r') msg << "a carriage return without a line feed (old Mac line ends): use \\n or \\r\\n";
      else msg << "control character 0x" << std::hex << std::setw(2) << std::setfill('0') << int(c)
               << " (lines hold text, spaces and tabs)";
      throw Error(msg.str());
    }
  }
}

// Splits at spaces and tabs.
std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> tokens;
  size_t start = 0;
  while ((start = line.find_first_not_of(" \t", start)) != std::string::npos) {
    const size_t end = line.find_first_of(" \t", start);
    tokens.push_back(line.substr(start, end == std::string::npos ? std::string::npos : end - start));
    start = end;
  }
  return tokens;
}

struct LineReader {
  const std::string& text;
  std::string name;
  size_t pos;
  int number = 0;
  std::string content;  // the current line without its final CR and comment

  LineReader(const std::string& t, std::string n) : text(t), name(std::move(n)), pos(bomLength(t)) {
    requirePlainText(text, name, pos);
  }

  // The next line split into tokens at spaces and tabs, comments and a final CR removed.
  bool next(std::vector<std::string>& tokens) {
    if (pos >= text.size()) return false;
    size_t end = text.find('\n', pos);
    if (end == std::string::npos) end = text.size();
    content.assign(text, pos, end - pos);
    pos = end + 1;
    ++number;
    if (!content.empty() && content.back() == '\r') content.pop_back();
    if (const auto hash = content.find('#'); hash != std::string::npos) content.erase(hash);
    tokens = split(content);
    return true;
  }

  std::string where() const { return name + ":" + std::to_string(number); }

  [[noreturn]] void fail(const std::string& what) const { throw Error(where() + ": " + what); }
};

enum class NumberSyntax { ok, notANumber, nonFinite, hexadecimal, tooManyDigits, exponentTooLarge };

// A number as the lint accepts it (obj_lint.h): what tinyobjloader's tryParseDouble reads to
// strtod's value. It stops at the first character outside its grammar and keeps what it read
// (`1.0abc` is 1, `0x1p3` is 0), fails on an empty exponent (`1e`: the field's default), and
// computes mantissa * 5^e * 2^e in doubles: with more than ~300 digits the mantissa
// overflows, and 5^e overflows beyond e = 441 (`0e999` is 0 * inf, NaN). The bounds keep well
// inside both.
NumberSyntax numberSyntax(const std::string& t, double& value) {
  const size_t n = t.size();
  size_t i = 0;
  if (i < n && (t[i] == '+' || t[i] == '-')) ++i;
  const size_t unsignedStart = i;
  size_t digits = 0;
  while (i < n && isDigit(t[i])) ++i, ++digits;
  if (i < n && t[i] == '.') {
    ++i;
    while (i < n && isDigit(t[i])) ++i, ++digits;
  }
  bool ok = digits > 0;
  long exponent = 0;
  if (ok && i < n && (t[i] == 'e' || t[i] == 'E')) {
    ++i;
    bool negative = false;
    if (i < n && (t[i] == '+' || t[i] == '-')) negative = t[i++] == '-';
    const size_t first = i;
    while (i < n && isDigit(t[i])) {
      if (exponent <= 100000) exponent = 10 * exponent + (t[i] - '0');
      ++i;
    }
    ok = i > first;
    if (negative) exponent = -exponent;
  }
  if (!ok || i != n) {
    const std::string word = lower(t.substr(unsignedStart));
    if (word == "inf" || word == "infinity" || word == "nan" || word.rfind("nan(", 0) == 0)
      return NumberSyntax::nonFinite;
    if (word.rfind("0x", 0) == 0) return NumberSyntax::hexadecimal;
    return NumberSyntax::notANumber;
  }
  if (digits > kMaxDigits) return NumberSyntax::tooManyDigits;
  if (exponent > kMaxExponent || exponent < -kMaxExponent) return NumberSyntax::exponentTooLarge;
  value = std::strtod(t.c_str(), nullptr);
  return NumberSyntax::ok;
}

// A number for `key` read as a float; fails naming the token and what is wrong with it.
float requireNumber(const LineReader& r, const std::string& token, const std::string& key) {
  double v = 0.0;
  const std::string in = " in '" + key + "'";
  switch (numberSyntax(token, v)) {
    case NumberSyntax::ok: break;
    case NumberSyntax::nonFinite: r.fail("non-finite value '" + token + "'" + in);
    case NumberSyntax::hexadecimal:
      r.fail("'" + token + "' is not a number" + in + " (hexadecimal numbers are not read: write it in decimal)");
    case NumberSyntax::tooManyDigits:
      r.fail("'" + token + "' is not a number" + in + " (more than " + std::to_string(kMaxDigits) + " digits)");
    case NumberSyntax::exponentTooLarge:
      r.fail("'" + token + "' is not a number" + in + " (an exponent beyond +-" + std::to_string(kMaxExponent) + ")");
    case NumberSyntax::notANumber: r.fail("'" + token + "' is not a number" + in);
  }
  const float f = static_cast<float>(v);
  if (!std::isfinite(f)) r.fail("non-finite value '" + token + "'" + in + " (beyond the float range)");
  return f;
}

// Checks tokens[first ..] are between minCount and maxCount numbers the loader reads right;
// returns them.
std::vector<float> requireNumbers(const LineReader& r, const std::vector<std::string>& tokens, size_t first,
                                  size_t minCount, size_t maxCount, const char* what) {
  const size_t n = tokens.size() - first;
  if (n < minCount || n > maxCount) {
    std::ostringstream msg;
    msg << "'" << tokens[0] << "' needs ";
    if (minCount == maxCount) msg << minCount;
    else msg << minCount << " to " << maxCount;
    msg << " numbers (" << what << "), got " << n;
    r.fail(msg.str());
  }
  std::vector<float> values;
  for (size_t i = first; i < tokens.size(); ++i) values.push_back(requireNumber(r, tokens[i], tokens[0]));
  return values;
}

// Appends the tokens joined by single spaces, and the line end: the canonical line.
void appendLine(std::string& out, const std::vector<std::string>& tokens, size_t count) {
  for (size_t i = 0; i < count && i < tokens.size(); ++i) {
    if (i) out += ' ';
    out += tokens[i];
  }
  out += '\n';
}

struct IndexCheck {
  long maxPositive = 0;  // largest 1-based index seen, checked against the final count
  int maxPositiveLine = 0;
};

// One of v, v/t, v//n, v/t/n: checks each index is a nonzero integer and that relative
// (negative) ones point at an element already defined.
void checkFaceToken(const LineReader& r, const std::string& token, const size_t counts[3], IndexCheck checks[3]) {
  static const char* kinds[3] = {"vertex", "texture coordinate", "normal"};
  // "1/" and "1//": tinyobjloader reads a missing index after a final slash as index 0.
  if (token.back() == '/') r.fail("face element '" + token + "' ends in '/' (give the index or drop the slash)");
  size_t start = 0;
  for (int slot = 0; slot < 3 && start <= token.size(); ++slot) {
    const size_t slash = token.find('/', start);
    const std::string part = token.substr(start, slash == std::string::npos ? std::string::npos : slash - start);
    start = slash == std::string::npos ? token.size() + 1 : slash + 1;
    if (part.empty()) {
      if (slot == 0) r.fail("face element '" + token + "' has no vertex index");
      continue;
    }
    // tinyobjloader reads indices with atoi: digits after an optional sign, nothing else.
    const size_t signs = (part[0] == '+' || part[0] == '-') ? 1 : 0;
    if (part.size() == signs || !std::all_of(part.begin() + long(signs), part.end(), isDigit))
      r.fail("face element '" + token + "' has a non-integer index '" + part + "'");
    const std::string digits = part.substr(signs);
    const size_t significant = digits.find_first_not_of('0');
    if (significant != std::string::npos && digits.size() - significant > 10)
      r.fail("face element '" + token + "' has an index out of any file's range");
    const long magnitude =
        significant == std::string::npos ? 0 : std::strtol(digits.c_str() + significant, nullptr, 10);
    if (magnitude > kMaxIndex) r.fail("face element '" + token + "' has an index out of any file's range");
    const long index = part[0] == '-' ? -magnitude : magnitude;
    if (index == 0) r.fail("face element '" + token + "' uses index 0 (OBJ indices start at 1)");
    if (index < 0) {
      if (static_cast<size_t>(-index) > counts[slot]) {
        std::ostringstream msg;
        msg << "relative " << kinds[slot] << " index " << index << " out of range (" << counts[slot]
            << " defined so far)";
        r.fail(msg.str());
      }
    } else if (index > checks[slot].maxPositive) {
      checks[slot].maxPositive = index;
      checks[slot].maxPositiveLine = r.number;
    }
  }
  if (start <= token.size()) r.fail("face element '" + token + "' has more than three indices");
}

// Statements of one kind the renderer does not use: counted, and warned about once.
class IgnoredStatements {
 public:
  void add(const std::string& kind, int line, const std::string& why, const std::string& material = "") {
    auto it = kinds_.find(kind);
    if (it == kinds_.end()) {
      it = kinds_.emplace(kind, Kind{0, line, why, material}).first;
      order_.push_back(kind);
    }
    ++it->second.count;
  }

  void warn(const std::string& name, std::vector<std::string>& warnings) const {
    for (size_t i = 0; i < order_.size() && i < kMaxKindWarnings; ++i) {
      const Kind& k = kinds_.at(order_[i]);
      std::ostringstream msg;
      msg << name << ":" << k.line << ": " << k.why << " (" << k.count << " statement" << (k.count == 1 ? "" : "s");
      if (!k.material.empty()) msg << ", the first in material '" << k.material << "'";
      msg << ")";
      warnings.push_back(msg.str());
    }
    if (order_.size() > kMaxKindWarnings) {
      size_t statements = 0;
      for (size_t i = kMaxKindWarnings; i < order_.size(); ++i) statements += kinds_.at(order_[i]).count;
      warnings.push_back(name + ": " + std::to_string(order_.size() - kMaxKindWarnings) + " more kinds of statement (" +
                         std::to_string(statements) + " in all) ignored");
    }
  }

 private:
  struct Kind {
    size_t count;
    int line;
    std::string why;
    std::string material;
  };
  std::map<std::string, Kind> kinds_;
  std::vector<std::string> order_;  // by first appearance
};

// ---- Files in other formats ----

uint32_t littleEndian32(const std::string& text, size_t at) {
  uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | uint32_t(static_cast<unsigned char>(text[at + size_t(i)]));
  return v;
}

// What the file looks like when it is plainly not OBJ text, else "".
std::string otherFormat(const std::string& text, size_t start) {
  if (hasAt(text, 0, "\xFF\xFE") || hasAt(text, 0, "\xFE\xFF")) return "it is UTF-16 text: save it as UTF-8";
  if (hasAt(text, start, "ply\n") || hasAt(text, start, "ply\r\n")) return "it looks like a PLY file";
  if (hasAt(text, start, "glTF")) return "it looks like a binary glTF (.glb) file";
  if (text.size() >= 84 && 84 + 50 * uint64_t(littleEndian32(text, 80)) == text.size())
    return "it looks like a binary STL file";
  if (hasAt(text, start, "Kaydara FBX Binary") || hasAt(text, start, "; FBX")) return "it looks like an FBX file";
  if (hasAt(text, start, "PK\x03\x04")) return "it looks like a ZIP archive: unpack it first";
  if (hasAt(text, start, "\x1f\x8b")) return "it looks like a gzip file: unpack it first";
  const size_t first = text.find_first_not_of(" \t\r\n", start);
  if (first == std::string::npos) return "";
  const std::string head = lower(text.substr(first, 4096));
  if (head[0] == '<') {
    if (head.find("<collada") != std::string::npos) return "it looks like a COLLADA (.dae) file";
    if (head.find("<scene") != std::string::npos) return "it looks like a Mitsuba XML scene";
    if (head.find("<x3d") != std::string::npos) return "it looks like an X3D file";
    return "it looks like an XML file";
  }
  if (head[0] == '{')
    return head.find("\"asset\"") != std::string::npos ? "it looks like a glTF file" : "it looks like a JSON file";
  if (head.rfind("solid", 0) == 0 && head.find("facet") != std::string::npos) return "it looks like an ASCII STL file";
  if (head.rfind("#usda", 0) == 0) return "it looks like a USD file";
  if (head.rfind("#vrml", 0) == 0) return "it looks like a VRML file";
  const std::string firstLine = head.substr(0, head.find_first_of("\r\n"));
  if (firstLine == "off" || firstLine == "coff" || firstLine == "noff") return "it looks like an OFF file";
  return "";
}

// The statements of OBJ geometry fredholm reads (the rest are warned about and blanked).
bool isObjStatement(const std::string& key) {
  return key == "v" || key == "vt" || key == "vn" || key == "f" || key == "mtllib" || key == "usemtl" ||
         key == "o" || key == "g" || key == "s";
}

// Other statements of the OBJ specification: not surfaces fredholm renders.
bool isOtherObjStatement(const std::string& key) {
  static const std::set<std::string> keys = {
      "l",      "p",      "vp",  "cstype", "deg",      "bmat",     "step",       "curv",      "curv2", "surf", "parm",
      "trim",   "hole",   "scrv", "sp",    "end",      "con",      "mg",         "usemap",    "maplib", "lod", "bevel",
      "c_interp", "d_interp", "shadow_obj", "trace_obj", "ctech", "stech", "call", "csh", "vw"};
  return keys.count(key) > 0;
}

// Binary data: a control character before any line that starts with an OBJ statement.
std::string binaryData(const std::string& text, size_t start) {
  size_t bad = start;
  while (bad < text.size() && !isControl(static_cast<unsigned char>(text[bad]))) ++bad;
  if (bad == text.size()) return "";
  for (size_t line = start; line < bad;) {
    size_t end = text.find('\n', line);
    if (end == std::string::npos || end > bad) end = bad;
    const std::vector<std::string> t = split(text.substr(line, end - line));
    if (!t.empty() && (isObjStatement(t[0]) || isOtherObjStatement(t[0]))) return "";
    line = end + 1;
  }
  std::ostringstream msg;
  msg << "binary data: byte 0x" << std::hex << std::setw(2) << std::setfill('0')
      << int(static_cast<unsigned char>(text[bad])) << std::dec << " at offset " << bad;
  return msg.str();
}

// The shortest decimal that reads back as `v` (0.2f as 0.2, not 0.200000003).
std::string number(float v) {
  char buffer[32];
  for (int precision = 6; precision <= 9; ++precision) {
    std::snprintf(buffer, sizeof buffer, "%.*g", precision, double(v));
    if (std::strtof(buffer, nullptr) == v) break;
  }
  return buffer;
}

std::string rgb(const float c[3]) { return number(c[0]) + " " + number(c[1]) + " " + number(c[2]); }

}  // namespace

ObjLintReport lintObj(const std::string& text, const std::string& name) {
  const size_t start = bomLength(text);
  if (std::string format = otherFormat(text, start); !format.empty())
    throw Error(name + ": not an OBJ file (" + format + ")");
  if (std::string binary = binaryData(text, start); !binary.empty())
    throw Error(name + ": not an OBJ file (" + binary + ")");

  ObjLintReport report;
  report.text.reserve(text.size());
  LineReader r(text, name);
  size_t counts[3] = {0, 0, 0};  // v, vt, vn
  IndexCheck checks[3];
  std::set<std::string> usemtlSeen;
  IgnoredStatements ignored;
  bool objStatements = false, mtllibWritten = false;
  int firstStatementLine = 0;
  std::string firstStatement;

  std::vector<std::string> t;
  while (r.next(t)) {
    if (t.empty()) {
      report.text += '\n';
      continue;
    }
    const std::string& key = t[0];
    if (firstStatement.empty()) {
      firstStatement = key;
      firstStatementLine = r.number;
    }
    size_t keep = t.size();  // tokens passed on to tinyobjloader; 0 blanks the line
    if (key == "v") {
      requireNumbers(r, t, 1, 3, 7, "x y z [w] or x y z r g b");
      ++counts[0];
    } else if (key == "vt") {
      requireNumbers(r, t, 1, 1, 3, "u [v [w]]");
      ++counts[1];
    } else if (key == "vn") {
      requireNumbers(r, t, 1, 3, 3, "x y z");
      ++counts[2];
    } else if (key == "f") {
      if (t.size() < 4) r.fail("face needs at least three vertices, got " + std::to_string(t.size() - 1));
      for (size_t i = 1; i < t.size(); ++i) checkFaceToken(r, t[i], counts, checks);
      ++report.faces;
    } else if (key == "mtllib") {
      if (t.size() < 2) r.fail("'mtllib' without a file name");
      for (size_t i = 1; i < t.size(); ++i) report.mtllibs.push_back({t[i], r.number});
      // tinyobjloader reads the (concatenated) MTL text at its first mtllib; at a second it
      // would read an empty stream and add a material without a name.
      keep = mtllibWritten ? 0 : t.size();
      mtllibWritten = true;
    } else if (key == "usemtl") {
      if (t.size() < 2) r.fail("'usemtl' without a material name");
      if (usemtlSeen.insert(t[1]).second) report.usemtls.push_back({t[1], r.number});
      keep = 2;  // tinyobjloader reads the first word
    } else if (key == "o" || key == "g" || key == "s") {
      // Grouping and smoothing: nothing to check.
    } else if (isOtherObjStatement(key)) {
      ignored.add(key, r.number, "ignored '" + key + "': fredholm renders polygonal faces only");
      keep = 0;
    } else {
      ignored.add(key, r.number, "ignored unknown statement '" + key + "'");
      keep = 0;
    }
    objStatements = objStatements || keep > 0 || isOtherObjStatement(key);
    appendLine(report.text, t, keep);
  }
  if (report.faces == 0) {
    if (!objStatements && !firstStatement.empty())
      throw Error(name + ": not an OBJ file (no line holds an OBJ statement; the first reads '" +
                  firstStatement.substr(0, 40) + "' at line " + std::to_string(firstStatementLine) + ")");
    throw Error(name + ": no faces (an empty OBJ, or one with only vertices)");
  }
  static const char* kinds[3] = {"vertex", "texture coordinate", "normal"};
  for (int slot = 0; slot < 3; ++slot) {
    if (static_cast<size_t>(checks[slot].maxPositive) > counts[slot]) {
      std::ostringstream msg;
      msg << name << ":" << checks[slot].maxPositiveLine << ": " << kinds[slot] << " index "
          << checks[slot].maxPositive << " out of range (the file defines " << counts[slot] << ")";
      throw Error(msg.str());
    }
  }
  ignored.warn(name, report.warnings);
  return report;
}

namespace {

// One material as the MTL lint reads it: its lines are held until the material ends, when
// what only the whole material tells (its illum model) decides which reflectances matter.
struct PendingMaterial {
  std::string name;
  int line = 0;
  bool keep = true;
  std::vector<std::string> lines;  // canonical, without line ends
  int illum = 0;                   // tinyobjloader's default
  struct Colour {
    float value[3] = {0.f, 0.f, 0.f};
    size_t at = SIZE_MAX;  // index in `lines` of the statement that set it last
    int line = 0;
    std::string key;  // as that statement spelled it (Tf or Kt)
  } kd, ks, tf;
};

// Scales a reflectance the renderer uses down to a largest channel of one (hue kept).
void conserve(PendingMaterial& m, PendingMaterial::Colour& c, const char* what, const std::string& file,
              std::vector<std::string>& warnings) {
  if (c.at == SIZE_MAX) return;
  const float before[3] = {c.value[0], c.value[1], c.value[2]};
  if (!capReflectance(c.value)) return;
  m.lines[c.at] = c.key + " " + rgb(c.value);
  warnings.push_back(file + ":" + std::to_string(c.line) + ": material '" + m.name + "': " + c.key + " " + rgb(before) +
                     " " + what + " more light than it receives; scaled down to " + rgb(c.value));
}

// A glass model's reflectance is Fresnel's, from Ni, and its transmission is tinted by Tf
// (kernels/bsdf.h): a Kd or Ks above zero, which the MTL models would use, is not. Said once
// a material, at the first such statement's line.
void warnUnusedByGlass(const PendingMaterial& m, const std::string& file, std::vector<std::string>& warnings) {
  std::string unused;
  int line = 0;
  for (const PendingMaterial::Colour* c : {&m.kd, &m.ks})
    if (c->at != SIZE_MAX && std::max({c->value[0], c->value[1], c->value[2]}) > 0.f) {
      unused += (unused.empty() ? "" : " and ") + c->key + " " + rgb(c->value);
      line = line ? std::min(line, c->line) : c->line;
    }
  if (!unused.empty())
    warnings.push_back(file + ":" + std::to_string(line) + ": material '" + m.name + "': " + unused +
                       " not used by glass (illum " + std::to_string(m.illum) +
                       "): it reflects by Fresnel's law from Ni, and Tf tints what it transmits");
}

void flush(PendingMaterial& m, const std::string& file, std::string& out, std::vector<std::string>& warnings) {
  if (m.keep) {
    if (isGlassIllum(m.illum)) {
      conserve(m, m.tf, "transmits", file, warnings);
      warnUnusedByGlass(m, file, warnings);
    } else {
      // The BSDF (kernels/bsdf.h) conserves energy when Kd and Ks are each at most one: the
      // diffuse lobe gets only what the specular lobe's Fresnel leaves over.
      conserve(m, m.kd, "reflects", file, warnings);
      if (m.illum >= 2) conserve(m, m.ks, "reflects", file, warnings);
    }
    for (const std::string& l : m.lines) (out += l) += '\n';
  } else {
    out.append(m.lines.size(), '\n');
  }
  m.lines.clear();
}

bool isColour(const std::string& key) {
  return key == "Ka" || key == "Kd" || key == "Ks" || key == "Ke" || key == "Tf" || key == "Kt";
}

// Statements of one number fredholm does not use.
bool isIgnoredScalar(const std::string& key) {
  static const std::set<std::string> keys = {"sharpness", "Pr", "Pm", "Ps", "Pc", "Pcr", "aniso", "anisor", "Pwr"};
  return keys.count(key) > 0;
}

bool isMap(const std::string& key) {
  return key.rfind("map_", 0) == 0 || key == "bump" || key == "disp" || key == "decal" || key == "refl" ||
         key == "norm";
}

// tinyobjloader's texture options (ParseTextureNameAndOption); fredholm applies none.
bool isTextureOption(const std::string& token) {
  static const std::set<std::string> options = {"-blendu", "-blendv", "-bm",     "-boost", "-cc",
                                                "-clamp",  "-imfchan", "-mm",    "-o",     "-s",
                                                "-t",      "-texres", "-type",   "-colorspace"};
  return options.count(token) > 0;
}

}  // namespace

MtlLintReport lintMtl(const std::string& text, const std::string& name, const std::set<std::string>* used) {
  MtlLintReport report;
  LineReader r(text, name);
  IgnoredStatements ignored;
  std::map<std::string, int> firstDefinition;
  PendingMaterial m;  // before the first newmtl: the preamble, kept
  std::vector<std::string> t;
  while (r.next(t)) {
    std::string canonical;  // this line as tinyobjloader will read it; empty blanks it
    if (t.empty()) {
      m.lines.push_back(canonical);
      continue;
    }
    const std::string& key = t[0];
    const bool inMaterial = !report.materials.empty();
    const std::string material = inMaterial ? "material '" + m.name + "': " : "";
    const bool known = isColour(key) || isIgnoredScalar(key) || isMap(key) || key == "Ns" || key == "Ni" ||
                       key == "d" || key == "Tr" || key == "illum";
    if (known && !inMaterial) r.fail("'" + key + "' before any 'newmtl'");
    const bool warn = m.keep;  // ignored statements are reported for the materials used
    if (key == "newmtl") {
      if (t.size() < 2) r.fail("'newmtl' without a material name");
      flush(m, name, report.text, report.warnings);
      m = PendingMaterial{};
      m.name = t[1];  // usemtl reads one word; tinyobjloader would read the rest of the line
      m.line = r.number;
      m.keep = !used || used->count(m.name) > 0;
      report.materials.push_back(m.name);
      if (m.keep) {
        const auto [it, first] = firstDefinition.emplace(m.name, r.number);
        if (!first)
          report.warnings.push_back(r.where() + ": material '" + m.name +
                                    "' is defined again; the first definition (line " + std::to_string(it->second) +
                                    ") is used");
      }
      canonical = "newmtl " + m.name;
    } else if (isColour(key)) {
      if (t.size() > 1 && (t[1] == "spectral" || t[1] == "xyz"))
        r.fail("MTL " + t[1] + " colours are not supported ('" + key + " " + t[1] + "'): give r g b");
      if (t.size() == 3) r.fail("'" + key + "' needs one or three numbers (r g b, or one for grey), got 2");
      const std::vector<float> v = requireNumbers(r, t, 1, 1, 3, "r g b, or one for grey");
      float c[3] = {v[0], v.size() == 3 ? v[1] : v[0], v.size() == 3 ? v[2] : v[0]};
      if (c[0] < 0.f || c[1] < 0.f || c[2] < 0.f)
        r.fail(material + "negative " + key + " " + rgb(c) + ": colours cannot be below 0");
      canonical = key + " " + rgb(c);
      PendingMaterial::Colour* target = key == "Kd"                ? &m.kd
                                        : key == "Ks"                ? &m.ks
                                        : key == "Tf" || key == "Kt" ? &m.tf
                                                                     : nullptr;
      if (target) {
        std::copy(c, c + 3, target->value);
        target->at = m.lines.size();
        target->line = r.number;
        target->key = key;
      }
    } else if (key == "Ns" || key == "Ni" || key == "d" || key == "Tr") {
      const float v = requireNumbers(r, t, 1, 1, 1, "one value")[0];
      if (key == "Ns" && v < 0.f) r.fail(material + "negative Ns " + number(v) + ": a specular exponent is at least 0");
      if (key == "Ni" && !(v > 0.f))
        r.fail(material + "Ni " + number(v) + ": an index of refraction is greater than 0 (glass is about 1.5)");
      if (key == "d" && v != 1.f && warn)
        ignored.add("d", r.number, "'d' (dissolve) other than 1 is ignored: fredholm renders every surface opaque",
                    m.name);
      if (key == "Tr" && v != 0.f && warn)
        ignored.add("Tr", r.number, "'Tr' (transparency) is ignored: fredholm renders every surface opaque", m.name);
      canonical = key + " " + number(v);
    } else if (key == "illum") {
      const float v = requireNumbers(r, t, 1, 1, 1, "one value")[0];
      if (v != std::floor(v) || std::fabs(v) > 1e9f) r.fail("'illum " + t[1] + "' is not a whole number");
      m.illum = int(v);
      if (m.illum < 0 || m.illum > 9) {
        if (warn)
          ignored.add("illum", r.number,
                      "illum " + std::to_string(m.illum) +
                          " is not a model fredholm renders (it knows 0 to 9); read as illum 2",
                      m.name);
        m.illum = 2;
      }
      canonical = "illum " + std::to_string(m.illum);
    } else if (isIgnoredScalar(key)) {
      requireNumbers(r, t, 1, 1, 1, "one value");
      if (warn) ignored.add(key, r.number, "'" + key + "' is ignored: fredholm does not use it", m.name);
    } else if (isMap(key)) {
      if (t.size() < 2) r.fail("'" + key + "' without a file name");
      if (key == "map_Kd") {
        // The file name is the rest of the line, spaces and all (as tinyobjloader reads it).
        const size_t at = r.content.find_first_not_of(" \t", r.content.find(key) + key.size());
        std::string rest = r.content.substr(at);
        rest.erase(rest.find_last_not_of(" \t") + 1);
        canonical = key + " " + rest;
        for (size_t i = 1; i < t.size(); ++i)
          if (isTextureOption(t[i]) && warn)
            ignored.add("map_Kd " + t[i], r.number,
                        "map_Kd option '" + t[i] + "' is ignored: fredholm does not apply it", m.name);
      } else if (warn) {
        ignored.add(key, r.number, "'" + key + "' is ignored: fredholm does not use it", m.name);
      }
    } else if (warn) {
      ignored.add(key, r.number, "ignored unknown statement '" + key + "'", inMaterial ? m.name : "");
    }
    m.lines.push_back(canonical);
  }
  flush(m, name, report.text, report.warnings);
  ignored.warn(name, report.warnings);
  return report;
}

}  // namespace fh
