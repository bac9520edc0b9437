// Checkpoints: a render's film saved while it runs (--checkpoint), and a render resumed from
// one (--resume). The film holds passes 0 .. n-1 merged in order, and a resumed render
// merges pass n onward into it in the same order and precision, so a render killed at any
// point and resumed gives the same image, to the bit, as one never interrupted.
#pragma once
#include <string>
#include <vector>

#include "render/film.h"
#include "render/settings.h"
#include "scene/camera.h"
#include "scene/scene.h"

namespace fh {

// What makes two renders the same image: the scene's geometry, materials and textures (by
// path), the camera, the scene's units (Scene::worldScale: the depth layer's), and the
// settings that change samples (size, seed, method, depths, vcm's merging radius,
// environment, filter, the sampler's replicates, the surface layers). Not the sample count
// or time (a resumed render may go further), nor the strategy or devices (all compute the
// same bits). A hex string.
std::string renderFingerprint(const Scene& scene, const Camera& camera, const RenderSettings& settings);

// Writes the film with the render's fingerprint, atomically (a temporary file renamed over
// `path`); errors name `flag`. The same format serves checkpoints and chunks (--film).
// Returns the path written (base/atomic_file.h).
std::string saveFilm(const std::string& path, const Film& film, const std::string& fingerprint, const std::string& flag);
void saveCheckpoint(const std::string& path, const Film& film, const std::string& fingerprint);

// The bytes of a film file with every checksum its header gives made anew over the sections
// as the header lays them out (those cut short: over what there is): for the fuzzer, whose
// mutations would otherwise stop at the first checksum, and tests that write a header by
// hand. Bytes whose first line is not a film header come back as they are.
std::string resealFilm(const std::string& bytes);

// A film file as saved: the film (its first pass and pass count included) and the
// fingerprint of the render that saved it. Throws fh::Error naming `flag` and the file if
// it cannot be read (not a regular file: base/input_file.h), is cut short, fails a section's
// checksum (a byte changed since it was saved) or is not consistent.
struct SavedFilm {
  Film film;
  std::string fingerprint;
};
SavedFilm readFilm(const std::string& path, const std::string& flag);

// The checkpoint saved at `path`; throws fh::Error naming `flag` and the file if it cannot
// be read, is cut short, was saved by another render (another fingerprint), or is a chunk
// that does not start at pass 0.
Film loadCheckpoint(const std::string& path, const std::string& fingerprint, const std::string& flag);

// The films saved at `paths` added into one (each may hold any passes), with the fingerprint
// they share: each saved by the render with `fingerprint` (empty: the first file's), no two
// holding a pass in common. Throws fh::Error naming `flag` and the file at fault.
SavedFilm mergeFilms(const std::vector<std::string>& paths, const std::string& fingerprint, const std::string& flag);

// Ranks sharing a render (host/distributed) checkpoint to a file each: `base`.rank<r>.
std::string rankCheckpointPath(const std::string& base, int rank);
// The files `base`.rank<r> there are, whatever the rank count that wrote them.
std::vector<std::string> rankCheckpointFiles(const std::string& base);
// Their films merged (mergeFilms), or, where there are none, the checkpoint `base` of a
// render of one process; throws fh::Error naming `flag` where mergeFilms does or for none.
Film loadRankCheckpoints(const std::string& base, const std::string& fingerprint, const std::string& flag);

}  // namespace fh
