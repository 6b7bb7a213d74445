// checkpoint.bin's identity and checksum (app/simulate/checkpoint_file.h).
#include "app/simulate/checkpoint_file.h"

#include <fstream>
#include <sstream>

#include "app/simulate/result_cache.h"
#include "core/errors.h"

namespace pneufem {

namespace {

const std::string kMagicLine = "pneufem checkpoint 2";  // the format's version: a new layout counts up (2: StateRecord::extrapolated)
const std::string kMagic = kMagicLine + "\n";
constexpr std::size_t kHexDigits = 16;  // one 64-bit FNV-1a hash
const std::string kChecksumTag = "checksum ";

std::string checksum_of(const std::string& bytes) {
  Fnv1a h;
  h.bytes(bytes.data(), bytes.size());
  return h.hex();
}

/// "run it again" with the command that does.
std::string run_again(const std::string& run_dir) {
  return "run it again: pneufem simulate " + run_dir + "/scene.toml --out " + run_dir;
}

/// The value of header line `name` at `pos` (advanced past it); "" if the line is not there.
std::string header_value(const std::string& text, std::size_t& pos, const std::string& name) {
  const std::size_t end = text.find('\n', pos);
  if (end == std::string::npos || text.compare(pos, name.size() + 1, name + " ") != 0) return "";
  std::string v = text.substr(pos + name.size() + 1, end - pos - name.size() - 1);
  pos = end + 1;
  return v;
}

}  // namespace

RunIdentity run_identity(const Scene& scene, const Model& model, const LoadHistory& load) {
  RunIdentity id;
  Fnv1a s;
  s.str(scene.to_toml());
  id.scene = s.hex();
  Fnv1a m;
  hash_mesh(m, model);
  id.mesh = m.hex();
  id.executable = executable_fingerprint();
  Fnv1a p;
  p.num(load.rest_between_trials_s);
  for (const TrialLoad& t : load.trials) {
    for (const std::vector<double>* v : {&t.time_s, &t.pressure_Pa, &t.output_s, &t.step_start_s, &t.step_end_s,
                                         &t.step_level_Pa})
      p.vec(*v);
    p.num(t.mark_s);
  }
  id.protocol = p.hex();
  return id;
}

std::string checkpoint_file_text(const RunIdentity& id, const std::string& body) {
  std::string text = kMagic;
  text += "scene " + id.scene + "\nmesh " + id.mesh + "\nexecutable " + id.executable + "\nprotocol " + id.protocol +
          "\nbody " + std::to_string(body.size()) + "\n";
  text += body;
  text += kChecksumTag + checksum_of(text) + "\n";
  return text;
}

std::string read_checkpoint_body(const std::filesystem::path& file, const RunIdentity& id, const std::string& run_dir) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string() + ": cannot be read; " + run_again(run_dir));
  std::stringstream buf;
  buf << in.rdbuf();
  const std::string text = buf.str();
  if (text.rfind(kMagic, 0) != 0)
    throw InputError(file.string() + ": not a checkpoint of this pneufem (no '" + kMagicLine +
                     "' header: another format, or not a checkpoint); the run cannot be resumed; " + run_again(run_dir));
  // The checksum line closes the file: "checksum <16 hex>\n".
  const std::size_t tail = kChecksumTag.size() + kHexDigits + 1;
  const bool has_tail = text.size() >= tail && text.back() == '\n' &&
                        text.compare(text.size() - tail, kChecksumTag.size(), kChecksumTag) == 0;
  if (!has_tail || text.substr(text.size() - tail + kChecksumTag.size(), kHexDigits) != checksum_of(text.substr(0, text.size() - tail)))
    throw InputError(file.string() + ": damaged (its checksum does not match: the file was changed or cut short); "
                     "the run cannot be resumed; " + run_again(run_dir));
  std::size_t pos = kMagic.size();
  const RunIdentity stored{header_value(text, pos, "scene"), header_value(text, pos, "mesh"),
                           header_value(text, pos, "executable"), header_value(text, pos, "protocol")};
  const std::string body_size = header_value(text, pos, "body");
  struct Field {
    const std::string &was, &now;
    const char* what;
  };
  const std::string mixing = "; resuming would mix two runs; ";
  for (const Field& p : {Field{stored.scene, id.scene, "its scene differs from scene.toml (a later run of another scene"
                                                     " was started in this directory)"},
                        Field{stored.mesh, id.mesh, "its mesh differs from the one scene.toml builds now (a changed deck?)"},
                        Field{stored.protocol, id.protocol, "its load protocol differs (a changed load.csv file?)"}})
    if (p.was != p.now) throw InputError(file.string() + " belongs to another run: " + p.what + mixing + run_again(run_dir));
  if (stored.executable != id.executable)
    throw InputError(file.string() + " was written by another build of pneufem (executable " + stored.executable +
                     ", this one " + id.executable + "); its state need not mean the same to this build: resume with "
                     "the build that wrote it, or " + run_again(run_dir));
  if (body_size.empty() || pos + std::stoull(body_size) + tail != text.size())
    throw InputError(file.string() + ": damaged (its header does not match its size); " + run_again(run_dir));
  return text.substr(pos, std::stoull(body_size));
}

}  // namespace pneufem
