// Line-level checks of OBJ and MTL text before tinyobjloader parses it. tinyobjloader
// skips or zero-fills what it cannot read and rarely says where; these checks turn bad
// input into an fh::Error naming "file:line" so a scene never loads silently wrong.
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
};

// Throws fh::Error("name:line: what") on: non-numeric or non-finite coordinates, faces
// with fewer than three vertices, zero or out-of-range indices, malformed index
// tokens, and a file with no faces at all.
ObjLintReport lintObj(const std::string& text, const std::string& name);

// Throws fh::Error("name:line: what") on: a statement before any `newmtl`, `newmtl`
// without a name, and colour or scalar fields that are not finite numbers.
// Returns the names of the materials it defines.
std::vector<std::string> lintMtl(const std::string& text, const std::string& name);

// The MTL text with only the materials in `used` (and what precedes the first newmtl),
// names read as the lint reads them (see obj_lint.cpp).
std::string keepUsedMaterials(const std::string& mtl, const std::set<std::string>& used);

}  // namespace fh
