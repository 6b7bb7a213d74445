#pragma once
// checkpoint.bin of a run directory (`simulate --resume`): the solver's and the application's state
// (the body, written by app/simulate/command.cpp), wrapped so that a resume never mixes two runs.
//
// The file records what it belongs to — FNV-1a hashes (app/simulate/result_cache.h) of the
// resolved scene, the built model's mesh, the executable and the load protocol — and ends in a
// checksum of everything before it:
//
//     pneufem checkpoint 1
//     scene <16 hex>
//     mesh <16 hex>
//     executable <16 hex>
//     protocol <16 hex>
//     body <bytes>
//     <body>
//     checksum <16 hex>
//
// FNV-1a changes for any change of one byte (each step is a bijection of the running hash), so a
// flipped bit is always found. A resume refuses a checkpoint of another scene, mesh, protocol or
// build with a message naming which differs.
#include <filesystem>
#include <string>

#include "engine/load_history.h"
#include "engine/model.h"
#include "scenes/scene.h"

namespace pneufem {

/// What a checkpoint belongs to, each an FNV-1a hash in hex.
struct RunIdentity {
  std::string scene;       ///< the resolved scene (Scene::to_toml)
  std::string mesh;        ///< the built model's mesh, boundary conditions, cavity faces, tip (hash_mesh)
  std::string executable;  ///< the running executable's bytes (executable_fingerprint)
  std::string protocol;    ///< the load history: every breakpoint, report time and rest
};

RunIdentity run_identity(const Scene& scene, const Model& model, const LoadHistory& load);

/// The file's bytes: the identity, `body` and the checksum.
std::string checkpoint_file_text(const RunIdentity& id, const std::string& body);

/// The body of checkpoint `file`, after checking that it is a checkpoint, that its checksum matches
/// and that it belongs to `id`; else an InputError naming the file, what is wrong and what to do
/// (`run_dir` is named in the command to run again).
std::string read_checkpoint_body(const std::filesystem::path& file, const RunIdentity& id, const std::string& run_dir);

}  // namespace pneufem
