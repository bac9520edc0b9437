// Line-level checks of OBJ and MTL text before tinyobjloader parses it. tinyobjloader
// skips or zero-fills what it cannot read and rarely says where; these checks turn bad
// input into an fh::Error naming "file:line" so a scene never loads silently wrong.
//
// The lint is also the only reader tinyobjloader listens to: each lint returns the text
// tinyobjloader parses, rewritten line for line (line N of the output is line N of the file)
// from what the lint read. A statement the lint does not read is blanked, a number it did not
// accept never reaches the loader, a single-value MTL colour is spelled as three, and a
// material's physically impossible values are refused or brought back into range.
#pragma once
#include <set>
#include <string>
#include <vector>

namespace fh {

struct ObjStatement {
  std::string argument;
  int line = 0;
};

struct ObjLintReport {
  std::vector<ObjStatement> mtllibs;  // each name given to `mtllib`, with its line
  std::vector<ObjStatement> usemtls;  // each distinct `usemtl` name, first line used
  size_t faces = 0;
  std::vector<std::string> warnings;
  std::string text;  // what tinyobjloader parses (see above)
};

// Numbers: [+-]? (digits [. digits?] | . digits) ([eE] [+-]? digits)?, at most 100 digits
// before the exponent and an exponent of at most 300: a subset of what tinyobjloader's
// tryParseDouble reads to the value strtod gives (it reads `0x1p3` as 0, `1.0abc` as 1, a
// failed `1e` as its default, and `0e999` as NaN).
//
// Throws fh::Error("name: not an OBJ file (...)") for a file in another format (PLY, STL,
// glTF, XML, binary data) and fh::Error("name:line: what") on: numbers outside the syntax
// tinyobjloader reads right (hex floats, inf, nan, `1e`, `1.0abc`), non-finite coordinates,
// faces with fewer than three vertices, zero or out-of-range indices, malformed index tokens,
// and a file with no faces at all. A UTF-8 byte order mark is skipped. Statements fredholm
// does not use are warned about once per kind, naming the first line.
ObjLintReport lintObj(const std::string& text, const std::string& name);

struct MtlLintReport {
  std::vector<std::string> materials;  // every material the file defines, in order
  std::vector<std::string> warnings;
  std::string text;  // what tinyobjloader parses (see above): the used materials only
};

// Throws fh::Error("name:line: what") on: a statement before any `newmtl`, `newmtl` without
// a name, numbers outside the syntax tinyobjloader reads right, a colour of two values,
// `spectral` and `xyz` colours, negative colours (Ka Kd Ks Ke Tf Kt), Ni <= 0, Ns < 0 and an
// illum that is not a whole number. One colour value means grey (`Kd 0.5` is 0.5 0.5 0.5).
// Warns (naming the material and line) where a reflectance the renderer uses exceeds one
// and scales it down, and once per kind for what the renderer ignores (d < 1, Tr, illum
// models it does not know, maps other than map_Kd, unknown statements).
// `used`: the materials to keep in `text` (and to warn about); nullptr keeps all.
MtlLintReport lintMtl(const std::string& text, const std::string& name,
                      const std::set<std::string>* used = nullptr);

}  // namespace fh
