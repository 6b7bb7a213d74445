#include "app/simulate/result_cache.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include <tbb/task_arena.h>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "core/version.h"

namespace pneufem {

namespace fs = std::filesystem;

namespace {

constexpr char kMagic[] = "pneufem cache 1\n";

enum class Entry { missing, damaged, valid };

/// Reads an entry into `v`: missing (no file), damaged (truncated, foreign, or failing its
/// checksum) or valid.
Entry read_entry(const std::string& path, std::vector<double>& v) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Entry::missing;
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t head = sizeof kMagic - 1;
  std::uint64_t n = 0, sum = 0;
  if (bytes.size() < head + 2 * sizeof n || bytes.compare(0, head, kMagic) != 0) return Entry::damaged;
  std::memcpy(&n, bytes.data() + head, sizeof n);
  if (n > (bytes.size() - head) / sizeof(double) || bytes.size() != head + sizeof n + n * sizeof(double) + sizeof sum)
    return Entry::damaged;
  v.resize(n);
  std::memcpy(v.data(), bytes.data() + head + sizeof n, n * sizeof(double));
  std::memcpy(&sum, bytes.data() + head + sizeof n + n * sizeof(double), sizeof sum);
  Fnv1a h;
  h.vec(v);
  return h.value() == sum ? Entry::valid : Entry::damaged;
}

std::string entry_bytes(const std::vector<double>& v) {
  std::string s(kMagic);
  const std::uint64_t n = v.size();
  Fnv1a h;
  h.vec(v);
  const std::uint64_t sum = h.value();
  s.append(reinterpret_cast<const char*>(&n), sizeof n);
  s.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(double));
  s.append(reinterpret_cast<const char*>(&sum), sizeof sum);
  return s;
}

}  // namespace

std::string Fnv1a::hex() const {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h_));
  return buf;
}

FileLock::FileLock(const std::string& path, const std::string& what) {
  fd_ = open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0 || flock(fd_, LOCK_EX) != 0) {
    if (fd_ >= 0) close(fd_);
    throw InputError(what + ": cannot lock " + path + " (is the directory writable?)");
  }
}

FileLock::~FileLock() { close(fd_); }

const std::string& executable_fingerprint() {
  static const std::string fp = [] {
    std::ifstream in("/proc/self/exe", std::ios::binary);
    Fnv1a h;
    h.str(version_string());
    if (in) {
      std::vector<char> buf(1 << 16);
      while (in.read(buf.data(), static_cast<std::streamsize>(buf.size())) || in.gcount() > 0)
        h.bytes(buf.data(), static_cast<std::size_t>(in.gcount()));
    }
    return h.hex();
  }();
  return fp;
}

void hash_model(Fnv1a& h, const Scene& scene, const Model& model) {
  h.str(scene.model_toml());
  hash_mesh(h, model);
}

void hash_mesh(Fnv1a& h, const Model& model) {
  std::vector<double> X;
  X.reserve(3 * model.mesh.X.size());
  for (const auto& x : model.mesh.X) X.insert(X.end(), {x.x(), x.y(), x.z()});
  h.vec(X);
  h.vec(model.mesh.conn);
  h.vec(model.element_part);
  h.vec(model.mesh.region);
  h.vec(model.fixed);
  std::vector<int> faces;
  for (const FaceRef& f : model.pressure_faces) faces.insert(faces.end(), {f.element, f.local_face});
  h.vec(faces);
  for (const MembraneSet& m : model.membranes) h.vec(m.nodes);
  h.vec(model.angle.tip_nodes);
}

std::vector<double> cached_doubles(const std::string& dir, const std::string& kind, const std::string& key,
                                   const std::function<std::vector<double>()>& compute, std::string* source) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (!fs::is_directory(dir)) throw InputError("--cache " + dir + ": cannot create the directory");
  const std::string base = (fs::path(dir) / (kind + "_" + key)).string();
  const std::string file = base + ".bin";
  std::vector<double> out;
  tbb::this_task_arena::isolate([&] {
    FileLock lock(base + ".lock", "--cache");
    const Entry e = read_entry(file, out);
    if (e == Entry::valid) {
      if (source) *source = "cache " + file;
      return;
    }
    out = compute();
    write_file_atomic(file, entry_bytes(out));
    if (source) *source = e == Entry::damaged ? "recomputed (" + file + " was damaged)" : "computed";
  });
  return out;
}

}  // namespace pneufem
