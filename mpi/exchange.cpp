#include "exchange.hpp"

#include "agree.hpp"

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>

namespace tc::mpi {

namespace {

constexpr int kTagSize = 101, kTagData = 102;
constexpr size_t kChunk = size_t(1) << 30;  // MPI counts are ints: send at most 1 GiB at once

class Packer {
 public:
  template <class T>
  void put(const T& x) {
    const char* p = reinterpret_cast<const char*>(&x);
    bytes_.insert(bytes_.end(), p, p + sizeof(T));
  }
  template <class T>
  void put(const std::vector<T>& v) {
    put(uint64_t(v.size()));
    const char* p = reinterpret_cast<const char*>(v.data());
    bytes_.insert(bytes_.end(), p, p + v.size() * sizeof(T));
  }
  void put(const std::string& s) {
    put(uint64_t(s.size()));
    bytes_.insert(bytes_.end(), s.begin(), s.end());
  }
  std::vector<char>& bytes() { return bytes_; }

 private:
  std::vector<char> bytes_;
};

class Unpacker {
 public:
  explicit Unpacker(const std::vector<char>& b) : b_(b) {}
  template <class T>
  void get(T& x) {
    take(&x, sizeof(T));
  }
  template <class T>
  void get(std::vector<T>& v) {
    uint64_t n = 0;
    get(n);
    if (n > (b_.size() - pos_) / sizeof(T)) throw std::runtime_error("a part's data is cut short");
    v.resize(size_t(n));
    take(v.data(), size_t(n) * sizeof(T));
  }
  void get(std::string& s) {
    std::vector<char> c;
    get(c);
    s.assign(c.begin(), c.end());
  }

 private:
  void take(void* out, size_t n) {
    if (n > b_.size() - pos_) throw std::runtime_error("a part's data is cut short");
    if (n) std::memcpy(out, b_.data() + pos_, n);
    pos_ += n;
  }
  const std::vector<char>& b_;
  size_t pos_ = 0;
};

void put_fields(Packer& p, const std::vector<Field>& fields) {
  p.put(uint64_t(fields.size()));
  for (const Field& f : fields) {
    p.put(f.name);
    p.put(int32_t(f.components));
    p.put(f.values);
  }
}

void get_fields(Unpacker& u, std::vector<Field>& fields) {
  uint64_t n = 0;
  u.get(n);
  fields.resize(size_t(n));
  for (Field& f : fields) {
    int32_t c = 0;
    u.get(f.name);
    u.get(c);
    f.components = c;
    u.get(f.values);
  }
}

}  // namespace

std::vector<char> pack(const Part& part) {
  const Mesh& m = part.mesh;
  Packer p;
  p.put(m.points);
  p.put(m.tets);
  p.put(uint64_t(m.tet_labels.size()));
  for (const Labels& l : m.tet_labels) {
    p.put(l.name);
    p.put(l.values);
  }
  put_fields(p, m.vertex_fields);
  put_fields(p, m.tet_fields);
  p.put(m.tris);
  p.put(m.tri_tags);
  p.put(m.edges);
  p.put(m.edge_tags);
  p.put(part.gid);
  p.put(part.frozen);
  p.put(part.select);
  p.put(part.field_points);
  p.put(part.field_values);
  p.put(part.field_tets);
  return std::move(p.bytes());
}

Part unpack(const std::vector<char>& bytes) {
  Part part;
  Mesh& m = part.mesh;
  Unpacker u(bytes);
  u.get(m.points);
  u.get(m.tets);
  uint64_t nl = 0;
  u.get(nl);
  m.tet_labels.resize(size_t(nl));
  for (Labels& l : m.tet_labels) {
    u.get(l.name);
    u.get(l.values);
  }
  get_fields(u, m.vertex_fields);
  get_fields(u, m.tet_fields);
  u.get(m.tris);
  u.get(m.tri_tags);
  u.get(m.edges);
  u.get(m.edge_tags);
  u.get(part.gid);
  u.get(part.frozen);
  u.get(part.select);
  u.get(part.field_points);
  u.get(part.field_values);
  u.get(part.field_tets);
  return part;
}

void send_part(const Part& part, int dest, MPI_Comm comm) {
  const std::vector<char> bytes = pack(part);
  const uint64_t n = bytes.size();
  MPI_Request request;
  MPI_Isend(&n, 1, MPI_UINT64_T, dest, kTagSize, comm, &request);
  wait_politely(request);
  for (size_t off = 0; off < n; off += kChunk) {
    MPI_Isend(bytes.data() + off, int(std::min(kChunk, n - off)), MPI_BYTE, dest, kTagData, comm, &request);
    wait_politely(request);
  }
}

Part recv_part(int source, MPI_Comm comm) {
  uint64_t n = 0;
  MPI_Request request;
  MPI_Irecv(&n, 1, MPI_UINT64_T, source, kTagSize, comm, &request);
  wait_politely(request);
  std::vector<char> bytes(static_cast<size_t>(n));
  for (size_t off = 0; off < n; off += kChunk) {
    MPI_Irecv(bytes.data() + off, int(std::min(kChunk, n - off)), MPI_BYTE, source, kTagData, comm, &request);
    wait_politely(request);
  }
  return unpack(bytes);
}

}  // namespace tc::mpi
