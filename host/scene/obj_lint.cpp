// OBJ/MTL line checks with file:line errors.
#include "scene/obj_lint.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <set>
#include <sstream>

#include "base/error.h"

namespace fh {
namespace {

// The lint must read the lines and tokens the loader (tinyobjloader) reads, or it checks
// other statements than those loaded. The two agree on lines that end in \n or \r\n and on
// tokens separated by spaces and tabs; they split differently at a lone \r (a line end to
// tinyobjloader), at \v, \f and NUL. Text holding those is refused, naming the line.
void requirePlainText(const std::string& text, const std::string& name) {
  int line = 1;
  for (size_t i = 0; i < text.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c == '\n') ++line;
    const bool crlf = c == '\r' && i + 1 < text.size() && text[i + 1] == '\n';
    if ((c < 0x20 && c != '\n' && c != '\t' && !crlf) || c == 0x7f) {
      std::ostringstream msg;
      msg << name << ":" << line << ": ";
      if (c == '\r') msg << "a carriage return without a line feed (old Mac line ends): use \\n or \\r\\n";
      else msg << "control character 0x" << std::hex << std::setw(2) << std::setfill('0') << int(c)
               << " (lines hold text, spaces and tabs)";
      throw Error(msg.str());
    }
  }
}

// One line's tokens, split at spaces and tabs, with a final CR and any comment removed.
std::vector<std::string> tokensOf(std::string line) {
  if (!line.empty() && line.back() == '\r') line.pop_back();
  if (const auto hash = line.find('#'); hash != std::string::npos) line.erase(hash);
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
  std::istringstream in;
  std::string name;
  int number = 0;

  LineReader(const std::string& text, std::string n) : in(text), name(std::move(n)) {
    requirePlainText(text, name);
  }

  // The next line split into tokens at spaces and tabs, comments and a final CR removed.
  bool next(std::vector<std::string>& tokens) {
    std::string line;
    if (!std::getline(in, line)) return false;
    ++number;
    tokens = tokensOf(line);
    return true;
  }

  [[noreturn]] void fail(const std::string& what) const {
    throw Error(name + ":" + std::to_string(number) + ": " + what);
  }
};

bool parseFloat(const std::string& token, float& value) {
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(token.c_str(), &end);
  if (end == token.c_str() || *end != '\0') return false;
  value = static_cast<float>(v);
  return true;
}

// Checks tokens[first .. first+count) are finite numbers.
void requireNumbers(const LineReader& r, const std::vector<std::string>& tokens, size_t first, size_t minCount,
                    size_t maxCount, const char* what) {
  const size_t n = tokens.size() - first;
  if (n < minCount || n > maxCount) {
    std::ostringstream msg;
    msg << "'" << tokens[0] << "' needs ";
    if (minCount == maxCount) msg << minCount;
    else msg << minCount << " to " << maxCount;
    msg << " numbers (" << what << "), got " << n;
    r.fail(msg.str());
  }
  for (size_t i = first; i < tokens.size(); ++i) {
    float v = 0.f;
    if (!parseFloat(tokens[i], v)) r.fail("'" + tokens[i] + "' is not a number in '" + tokens[0] + "'");
    if (!std::isfinite(v)) r.fail("non-finite value '" + tokens[i] + "' in '" + tokens[0] + "'");
  }
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
    char* end = nullptr;
    errno = 0;
    const long index = std::strtol(part.c_str(), &end, 10);
    if (*end != '\0') r.fail("face element '" + token + "' has a non-integer index '" + part + "'");
    if (errno == ERANGE || index < -(1L << 40) || index > (1L << 40))
      r.fail("face element '" + token + "' has an index out of any file's range");
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

}  // namespace

ObjLintReport lintObj(const std::string& text, const std::string& name) {
  ObjLintReport report;
  LineReader r(text, name);
  size_t counts[3] = {0, 0, 0};  // v, vt, vn
  IndexCheck checks[3];
  std::set<std::string> usemtlSeen;
  size_t unknown = 0;
  int firstUnknownLine = 0;
  std::string firstUnknown;

  std::vector<std::string> t;
  while (r.next(t)) {
    if (t.empty()) continue;
    const std::string& key = t[0];
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
    } else if (key == "usemtl") {
      if (t.size() < 2) r.fail("'usemtl' without a material name");
      if (usemtlSeen.insert(t[1]).second) report.usemtls.push_back({t[1], r.number});
    } else if (key == "o" || key == "g" || key == "s" || key == "l" || key == "p" || key == "vp" ||
               key == "usemap" || key == "maplib" || key == "mg" || key == "vw") {
      // Grouping, smoothing and non-surface elements: nothing to check.
    } else {
      if (unknown++ == 0) {
        firstUnknown = key;
        firstUnknownLine = r.number;
      }
    }
  }
  if (report.faces == 0) throw Error(name + ": no faces (an empty OBJ, or one with only vertices)");
  static const char* kinds[3] = {"vertex", "texture coordinate", "normal"};
  for (int slot = 0; slot < 3; ++slot) {
    if (static_cast<size_t>(checks[slot].maxPositive) > counts[slot]) {
      std::ostringstream msg;
      msg << name << ":" << checks[slot].maxPositiveLine << ": " << kinds[slot] << " index "
          << checks[slot].maxPositive << " out of range (the file defines " << counts[slot] << ")";
      throw Error(msg.str());
    }
  }
  if (unknown) {
    std::ostringstream msg;
    msg << name << ":" << firstUnknownLine << ": ignored " << unknown << " unknown statement(s), first '"
        << firstUnknown << "'";
    report.warnings.push_back(msg.str());
  }
  return report;
}

std::vector<std::string> lintMtl(const std::string& text, const std::string& name) {
  static const std::set<std::string> colours = {"Ka", "Kd", "Ks", "Ke", "Tf"};
  static const std::set<std::string> scalars = {"Ns", "Ni", "d", "Tr", "illum", "sharpness", "Pr", "Pm",
                                                "Ps", "Pc", "Pcr", "aniso", "anisor", "Pwr"};
  std::vector<std::string> materials;
  LineReader r(text, name);
  std::vector<std::string> t;
  while (r.next(t)) {
    if (t.empty()) continue;
    const std::string& key = t[0];
    if (key == "newmtl") {
      if (t.size() < 2) r.fail("'newmtl' without a material name");
      materials.push_back(t[1]);
      continue;
    }
    const bool known = colours.count(key) || scalars.count(key) || key.rfind("map_", 0) == 0 ||
                       key == "bump" || key == "disp" || key == "decal" || key == "refl" || key == "norm";
    if (known && materials.empty()) r.fail("'" + key + "' before any 'newmtl'");
    if (colours.count(key)) {
      if (t.size() > 1 && (t[1] == "spectral" || t[1] == "xyz"))
        r.fail("'" + key + " " + t[1] + "' colours are not supported; give r g b");
      requireNumbers(r, t, 1, 1, 3, "r [g b]");
      if (t.size() == 3) r.fail("'" + key + "' needs one or three numbers, got 2");
    } else if (scalars.count(key)) {
      requireNumbers(r, t, 1, 1, 1, "one value");
    } else if ((key.rfind("map_", 0) == 0 || key == "bump") && t.size() < 2) {
      r.fail("'" + key + "' without a file name");
    }
  }
  return materials;
}

// The MTL text with only the materials the OBJ uses (and what precedes the first newmtl):
// tinyobjloader keeps about 2 KB per material it reads, so a library of a million materials
// for a few faces would cost gigabytes. Names are read as the lint reads them.
std::string keepUsedMaterials(const std::string& mtl, const std::set<std::string>& used) {
  std::string kept;
  bool keeping = true;
  size_t start = 0;
  while (start < mtl.size()) {
    size_t end = mtl.find('\n', start);
    end = end == std::string::npos ? mtl.size() : end + 1;
    const std::string line = mtl.substr(start, end - start);
    const std::vector<std::string> t = tokensOf(line.substr(0, line.size() - (line.back() == '\n')));
    if (!t.empty() && t[0] == "newmtl") keeping = t.size() > 1 && used.count(t[1]) > 0;
    if (keeping) kept += line;
    start = end;
  }
  return kept;
}

}  // namespace fh
