// VTK XML UnstructuredGrid (.vtu): one Piece, DataArray format ascii / binary (base64,
// optionally zlib-compressed with vtkZLibDataCompressor block headers) / appended (raw
// or base64), header_type UInt32 or UInt64, either byte order, every numeric type.
// Reference: "VTK File Formats" (XML section) and vtkXMLDataParser for the block header.
//
// Why no XML library: the appended section is raw binary that follows "_" inside
// <AppendedData> and is not XML at all (an XML parser rejects it), and we want errors with
// line numbers in the XML part and byte offsets in the binary part. The scanner below only
// understands what VTK writes: tags with quoted attributes, comments, <?...?> and
// <!...> declarations, and text content (inline data) between tags.
#include <algorithm>
#include <cctype>
#include <cstring>
#include <limits>
#include <optional>

#include "io/io_util.hpp"
#include "io/vtk_common.hpp"
#include "tetcollapse/io.hpp"

namespace tc {

namespace {

using io::vtk::NumType;
using io::vtk::RawArray;

struct Tag {
  std::string name;
  size_t begin = 0;  // offset of '<'
  size_t end = 0;    // offset after '>'
  bool closing = false, self_closing = false;
  std::vector<std::pair<std::string, std::string>> attrs;
  const std::string* attr(std::string_view key) const {
    for (const auto& a : attrs)
      if (a.first == key) return &a.second;
    return nullptr;
  }
};

enum class Where { None, Points, Cells, PointData, CellData, Other };
enum class Encoding { Ascii, Binary, Appended };

struct ArrayDesc {
  std::string name;
  NumType type = NumType::Float64;
  int components = 1;
  Encoding format = Encoding::Ascii;
  size_t tag_pos = 0;                   // '<' of the DataArray tag
  size_t content_begin = 0, content_end = 0;
  uint64_t offset = 0;                  // appended
  std::optional<int64_t> tuples;        // NumberOfTuples when given
  Where where = Where::None;
};

std::string xml_unescape(std::string_view s) {
  std::string r;
  r.reserve(s.size());
  for (size_t i = 0; i < s.size(); ++i) {
    if (s[i] != '&') {
      r += s[i];
      continue;
    }
    static const struct { const char* ent; char c; } kEnt[] = {
        {"&amp;", '&'}, {"&lt;", '<'}, {"&gt;", '>'}, {"&quot;", '"'}, {"&apos;", '\''}};
    bool done = false;
    for (const auto& e : kEnt)
      if (s.substr(i, std::strlen(e.ent)) == e.ent) {
        r += e.c;
        i += std::strlen(e.ent) - 1;
        done = true;
        break;
      }
    if (!done) r += '&';
  }
  return r;
}

std::string xml_escape(const std::string& s) {
  std::string r;
  for (char c : s) {
    switch (c) {
      case '&': r += "&amp;"; break;
      case '<': r += "&lt;"; break;
      case '>': r += "&gt;"; break;
      case '"': r += "&quot;"; break;
      default: r += c;
    }
  }
  return r;
}

class VtuReader {
 public:
  VtuReader(const std::string& path, ReadNotes& notes) : file_(path), notes_(notes) {}

  Mesh read() {
    data_ = io::load_file(file_);
    if (data_.empty()) throw InputError(file_, "empty file");
    scan();
    return build();
  }

 private:
  std::string file_;
  ReadNotes& notes_;
  std::string data_;

  bool swap_ = false;            // data byte order differs from the host's
  size_t header_size_ = 4;       // UInt32 or UInt64 block headers
  bool compressed_ = false;
  bool appended_base64_ = false;
  size_t appended_begin_ = std::string::npos, appended_end_ = 0;
  bool have_piece_ = false;
  int64_t num_points_ = 0, num_cells_ = 0;
  size_t piece_pos_ = 0;
  std::vector<ArrayDesc> arrays_;
  std::vector<uint64_t> appended_offsets_;  // of every appended array, FieldData ones too

  int64_t line_of(size_t offset) const {
    offset = std::min(offset, data_.size());
    return 1 + std::count(data_.begin(), data_.begin() + std::ptrdiff_t(offset), '\n');
  }
  [[noreturn]] void fail_line(size_t offset, const std::string& reason) const {
    throw InputError(file_, line_of(offset), reason);
  }
  [[noreturn]] void fail_byte(size_t offset, const std::string& reason) const {
    throw InputError::at_byte(file_, int64_t(offset), reason);
  }

  // ------------------------------------------------------------ XML scanning

  static bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }
  static bool is_name_char(char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == ':' || c == '-' || c == '.';
  }

  // The next tag at or after pos; comments, <?...?> and <!...> are skipped. nullopt at the end.
  std::optional<Tag> next_tag(size_t& pos) const {
    for (;;) {
      size_t lt = data_.find('<', pos);
      if (lt == std::string::npos) {
        pos = data_.size();
        return std::nullopt;
      }
      if (data_.compare(lt, 4, "<!--") == 0) {
        size_t e = data_.find("-->", lt + 4);
        if (e == std::string::npos) fail_line(lt, "unterminated XML comment");
        pos = e + 3;
        continue;
      }
      if (data_.compare(lt, 2, "<?") == 0 || data_.compare(lt, 2, "<!") == 0) {
        size_t e = data_.find('>', lt);
        if (e == std::string::npos) fail_line(lt, "unterminated XML declaration");
        pos = e + 1;
        continue;
      }
      Tag t;
      t.begin = lt;
      size_t p = lt + 1;
      if (p < data_.size() && data_[p] == '/') {
        t.closing = true;
        ++p;
      }
      size_t ns = p;
      while (p < data_.size() && is_name_char(data_[p])) ++p;
      if (p == ns) fail_line(lt, "malformed XML tag");
      t.name = data_.substr(ns, p - ns);
      for (;;) {
        while (p < data_.size() && is_space(data_[p])) ++p;
        if (p >= data_.size()) fail_line(lt, "unterminated XML tag <" + t.name + ">");
        if (data_[p] == '>') {
          ++p;
          break;
        }
        if (data_[p] == '/' && p + 1 < data_.size() && data_[p + 1] == '>') {
          t.self_closing = true;
          p += 2;
          break;
        }
        size_t as = p;
        while (p < data_.size() && is_name_char(data_[p])) ++p;
        if (p == as) fail_line(p, "malformed attribute in <" + t.name + ">");
        std::string key = data_.substr(as, p - as);
        while (p < data_.size() && is_space(data_[p])) ++p;
        if (p >= data_.size() || data_[p] != '=') fail_line(p, "attribute " + key + " of <" + t.name + "> has no value");
        ++p;
        while (p < data_.size() && is_space(data_[p])) ++p;
        if (p >= data_.size() || (data_[p] != '"' && data_[p] != '\''))
          fail_line(p, "attribute " + key + " of <" + t.name + "> is not quoted");
        char q = data_[p++];
        size_t ve = data_.find(q, p);
        if (ve == std::string::npos) fail_line(as, "unterminated value of attribute " + key);
        t.attrs.emplace_back(std::move(key), xml_unescape(std::string_view(data_).substr(p, ve - p)));
        p = ve + 1;
      }
      t.end = p;
      pos = p;
      return t;
    }
  }

  int64_t int_attr(const Tag& t, const char* key, bool required, int64_t dflt = 0) const {
    const std::string* v = t.attr(key);
    if (!v) {
      if (required) fail_line(t.begin, "<" + t.name + "> has no " + key + " attribute");
      return dflt;
    }
    char* end = nullptr;
    errno = 0;
    long long x = std::strtoll(v->c_str(), &end, 10);
    if (v->empty() || end != v->c_str() + v->size() || errno == ERANGE || x < 0)
      fail_line(t.begin, std::string(key) + "=\"" + v->substr(0, 30) + "\" is not a non-negative integer");
    return x;
  }

  void scan() {
    size_t pos = 0;
    std::optional<Tag> root = next_tag(pos);
    if (!root || root->closing || root->name != "VTKFile")
      fail_line(root ? root->begin : 0, "not a VTK XML file (no <VTKFile> element)");
    const std::string* type = root->attr("type");
    if (!type || *type != "UnstructuredGrid")
      fail_line(root->begin, "VTKFile type '" + (type ? type->substr(0, 40) : std::string()) +
                                 "' is not supported (only UnstructuredGrid holds tetrahedra)");
    if (const std::string* bo = root->attr("byte_order")) {
      if (*bo != "LittleEndian" && *bo != "BigEndian")
        fail_line(root->begin, "unknown byte_order '" + bo->substr(0, 40) + "'");
      swap_ = (*bo == "LittleEndian") != io::vtk::kHostLittle;
    }
    if (const std::string* ht = root->attr("header_type")) {
      if (*ht == "UInt32") header_size_ = 4;
      else if (*ht == "UInt64") header_size_ = 8;
      else fail_line(root->begin, "unknown header_type '" + ht->substr(0, 40) + "' (UInt32 or UInt64)");
    }
    if (const std::string* c = root->attr("compressor")) {
      if (*c == "vtkZLibDataCompressor") compressed_ = true;
      else if (!c->empty()) fail_line(root->begin, "compressor '" + c->substr(0, 40) + "' is not supported (only vtkZLibDataCompressor)");
    }

    Where where = Where::None;
    while (auto t = next_tag(pos)) {
      if (t->closing) {
        if (t->name == "Points" || t->name == "Cells" || t->name == "PointData" || t->name == "CellData" ||
            t->name == "FieldData")
          where = Where::None;
        continue;
      }
      if (t->name == "Piece") {
        if (have_piece_) fail_line(t->begin, "more than one <Piece> (multi-piece files are not supported)");
        have_piece_ = true;
        piece_pos_ = t->begin;
        num_points_ = int_attr(*t, "NumberOfPoints", true);
        num_cells_ = int_attr(*t, "NumberOfCells", true);
        if (num_points_ > std::numeric_limits<int32_t>::max())
          fail_line(t->begin, "NumberOfPoints " + std::to_string(num_points_) + " is more than 2^31-1");
      } else if (t->name == "Points" || t->name == "Cells" || t->name == "PointData" || t->name == "CellData" ||
                 t->name == "FieldData") {
        if (!t->self_closing)
          where = t->name == "Points"      ? Where::Points
                  : t->name == "Cells"     ? Where::Cells
                  : t->name == "PointData" ? Where::PointData
                  : t->name == "CellData"  ? Where::CellData
                                           : Where::Other;
      } else if (t->name == "DataArray") {
        ArrayDesc a = describe(*t);
        a.where = where;
        if (!t->self_closing) {
          size_t close = data_.find("</DataArray", t->end);
          if (close == std::string::npos) fail_line(t->begin, "<DataArray> '" + a.name + "' is not closed");
          // VTK may put <InformationKey> elements before the data: the data follows the last '>'.
          size_t last_gt = data_.rfind('>', close);
          a.content_begin = std::max(t->end, last_gt == std::string::npos ? t->end : last_gt + 1);
          a.content_end = close;
          size_t gt = data_.find('>', close);
          pos = gt == std::string::npos ? data_.size() : gt + 1;
        }
        if (a.format == Encoding::Appended && !t->self_closing && a.content_begin != a.content_end &&
            std::any_of(data_.begin() + std::ptrdiff_t(a.content_begin), data_.begin() + std::ptrdiff_t(a.content_end),
                        [](char c) { return !is_space(c); }))
          fail_line(t->begin, "appended DataArray '" + a.name + "' has inline data");
        if (a.format == Encoding::Appended) appended_offsets_.push_back(a.offset);
        if (where != Where::Other) arrays_.push_back(std::move(a));
      } else if (t->name == "AppendedData") {
        const std::string* enc = t->attr("encoding");
        if (!enc || *enc == "raw") appended_base64_ = false;
        else if (*enc == "base64") appended_base64_ = true;
        else fail_line(t->begin, "unknown AppendedData encoding '" + enc->substr(0, 40) + "'");
        size_t u = data_.find('_', t->end);
        if (u == std::string::npos) fail_line(t->begin, "<AppendedData> without the '_' that starts the data");
        appended_begin_ = u + 1;
        // The raw data is not XML; the section ends at the last </AppendedData> of the file.
        size_t close = data_.rfind("</AppendedData>");
        appended_end_ = close == std::string::npos || close < appended_begin_ ? data_.size() : close;
        break;
      }
    }
    if (!have_piece_) fail_line(data_.size(), "no <Piece> in the file");
  }

  ArrayDesc describe(const Tag& t) const {
    ArrayDesc a;
    a.tag_pos = t.begin;
    const std::string* name = t.attr("Name");
    a.name = name ? *name : std::string();
    const std::string* type = t.attr("type");
    if (!type) fail_line(t.begin, "DataArray '" + a.name + "' has no type");
    if (!io::vtk::parse_xml_type(*type, a.type))
      fail_line(t.begin, "DataArray '" + a.name + "': unknown type '" + type->substr(0, 40) + "'");
    int64_t comps = int_attr(t, "NumberOfComponents", false, 1);
    if (comps < 1 || comps > 1024)
      fail_line(t.begin, "DataArray '" + a.name + "': NumberOfComponents " + std::to_string(comps) + " is not 1 to 1024");
    a.components = int(comps);
    if (t.attr("NumberOfTuples")) a.tuples = int_attr(t, "NumberOfTuples", true);
    const std::string* fmt = t.attr("format");
    if (!fmt || *fmt == "ascii") a.format = Encoding::Ascii;
    else if (*fmt == "binary") a.format = Encoding::Binary;
    else if (*fmt == "appended") a.format = Encoding::Appended;
    else fail_line(t.begin, "DataArray '" + a.name + "': unknown format '" + fmt->substr(0, 40) + "'");
    if (a.format == Encoding::Appended) a.offset = uint64_t(int_attr(t, "offset", true));
    return a;
  }

  // ------------------------------------------------------------ data

  // Base64 where VTK may have encoded the block header and the data separately: each
  // padded group ends a segment, and decoding restarts after it.
  bool base64_segments(std::string_view text, std::string& out) const {
    out.clear();
    std::string part;
    size_t p = 0;
    while (p < text.size()) {
      size_t eq = text.find('=', p);
      size_t end = eq == std::string_view::npos ? text.size() : eq;
      while (end < text.size() && (text[end] == '=' || is_space(text[end]))) ++end;
      std::string_view seg = text.substr(p, end - p);
      size_t chars = 0;
      for (char c : seg) chars += !is_space(c);
      if (eq != std::string_view::npos ? chars % 4 != 0 : chars % 4 == 1) return false;
      if (!io::base64_decode(seg, part)) return false;
      out += part;
      p = end;
    }
    return true;
  }

  uint64_t header_value(std::string_view bytes, size_t at) const {
    if (header_size_ == 4) {
      uint32_t v;
      std::memcpy(&v, bytes.data() + at, 4);
      return swap_ ? io::BinaryCursor::byteswap_value(v) : v;
    }
    uint64_t v;
    std::memcpy(&v, bytes.data() + at, 8);
    return swap_ ? io::BinaryCursor::byteswap_value(v) : v;
  }

  // The payload of a binary block (header + data, maybe compressed) that must hold exactly
  // `expected` bytes. `where` is the file offset reported in errors; `storage` keeps
  // inflated data alive.
  std::string_view block_payload(const ArrayDesc& a, std::string_view bytes, size_t where, uint64_t expected,
                                 std::string& storage) const {
    const std::string what = "DataArray '" + a.name + "'";
    const size_t hs = header_size_;
    if (!compressed_) {
      if (bytes.size() < hs) fail_byte(where, what + ": block header runs past the end of the data");
      uint64_t n = header_value(bytes, 0);
      if (n != expected)
        fail_byte(where, what + " holds " + std::to_string(n) + " bytes, expected " + std::to_string(expected));
      if (n > bytes.size() - hs)
        fail_byte(where, what + ": " + std::to_string(n) + " bytes run past the end of the data");
      return bytes.substr(hs, n);
    }
    if (bytes.size() < 3 * hs) fail_byte(where, what + ": compression header runs past the end of the data");
    const uint64_t nblocks = header_value(bytes, 0), block = header_value(bytes, hs), last = header_value(bytes, 2 * hs);
    if (nblocks > (bytes.size() - 3 * hs) / hs)
      fail_byte(where, what + ": " + std::to_string(nblocks) + " compressed blocks run past the end of the data");
    uint64_t total = 0;
    if (nblocks > 0) {
      if (block == 0 || last > block || nblocks - 1 > std::numeric_limits<uint64_t>::max() / block)
        fail_byte(where, what + ": bad compression header (block size " + std::to_string(block) + ")");
      total = (nblocks - 1) * block + (last ? last : block);
    }
    if (total != expected)
      fail_byte(where, what + " holds " + std::to_string(total) + " bytes, expected " + std::to_string(expected));
    // Check every block's sizes before allocating anything: the header's sizes are
    // counts taken from the file, and deflate inflates at most 1032:1, so a block that
    // claims more than that of its compressed size is refused instead of allocated.
    constexpr uint64_t kMaxDeflateRatio = 1032;
    const size_t first = 3 * hs + size_t(nblocks) * hs;
    for (size_t b = 0, p = first; b < nblocks; ++b) {
      const uint64_t csize = header_value(bytes, 3 * hs + b * hs);
      const uint64_t usize = b + 1 == nblocks && last ? last : block;
      if (csize > bytes.size() - p)
        fail_byte(where, what + ": compressed block " + std::to_string(b) + " runs past the end of the data");
      if (usize / kMaxDeflateRatio > csize)
        fail_byte(where, what + ": compressed block " + std::to_string(b) + " of " + std::to_string(csize) +
                             " bytes cannot inflate to " + std::to_string(usize) + " bytes");
      p += size_t(csize);
    }
    size_t p = first;
    storage.clear();
    storage.reserve(size_t(expected));
    std::string chunk;
    for (uint64_t b = 0; b < nblocks; ++b) {
      const uint64_t csize = header_value(bytes, 3 * hs + size_t(b) * hs);
      const uint64_t usize = b + 1 == nblocks && last ? last : block;
      if (!io::zlib_inflate(bytes.substr(p, size_t(csize)), chunk, size_t(usize)))
        fail_byte(where, what + ": compressed block " + std::to_string(b) + " is not valid zlib data of " +
                             std::to_string(usize) + " bytes");
      storage += chunk;
      p += size_t(csize);
    }
    return storage;
  }

  template <class T>
  void decode(const ArrayDesc& a, int64_t expected_values, std::vector<T>& out) const {
    const std::string what = "DataArray '" + a.name + "'";
    if (a.tuples && *a.tuples * a.components != expected_values)
      fail_line(a.tag_pos, what + ": NumberOfTuples " + std::to_string(*a.tuples) + " does not match the expected " +
                               std::to_string(expected_values / a.components));
    const size_t size = io::vtk::type_size(a.type);
    if (a.format == Encoding::Ascii) {
      io::TextCursor cur(std::string_view(data_).substr(0, a.content_end), file_);
      cur.set_pos(a.content_begin);
      if (expected_values > cur.max_items(2))
        cur.fail(what + ": " + std::to_string(expected_values) + " values are more than its text can hold");
      out.resize(size_t(expected_values));
      for (auto& v : out) {
        if constexpr (std::is_integral_v<T>) v = cur.next_int();
        else v = cur.next_double();
      }
      if (!cur.at_end()) cur.fail(what + ": more than the expected " + std::to_string(expected_values) + " values");
      return;
    }
    const uint64_t expected_bytes = uint64_t(expected_values) * size;
    std::string decoded, storage;
    std::string_view bytes;
    size_t where = 0;
    if (a.format == Encoding::Binary) {
      where = a.content_begin;
      if (!base64_segments(std::string_view(data_).substr(a.content_begin, a.content_end - a.content_begin), decoded))
        fail_byte(where, what + ": invalid base64 data");
      bytes = decoded;
    } else {
      if (appended_begin_ == std::string::npos) fail_line(a.tag_pos, what + " is appended, but the file has no <AppendedData>");
      if (a.offset > appended_end_ - appended_begin_)
        fail_line(a.tag_pos, what + ": offset " + std::to_string(a.offset) + " is past the end of the appended data");
      where = appended_begin_ + size_t(a.offset);
      // The array ends where the next one starts (or at the end of the appended data).
      size_t end = appended_end_;
      for (uint64_t o : appended_offsets_)
        if (o > a.offset && o <= appended_end_ - appended_begin_) end = std::min(end, appended_begin_ + size_t(o));
      std::string_view region = std::string_view(data_).substr(where, end - where);
      if (appended_base64_) {
        if (!base64_segments(region, decoded)) fail_byte(where, what + ": invalid base64 data");
        bytes = decoded;
      } else {
        bytes = region;
      }
    }
    if (expected_values < 0 || uint64_t(expected_values) > std::numeric_limits<uint64_t>::max() / 16)
      fail_byte(where, what + ": impossible number of values");
    std::string_view payload = block_payload(a, bytes, where, expected_bytes, storage);
    out.resize(size_t(expected_values));
    const int64_t bad = io::vtk::convert_raw(payload.data(), a.type, size_t(expected_values), swap_, out.data());
    if (bad >= 0) fail_byte(where, what + ": value " + std::to_string(bad + 1) + " is not an integer");
  }

  const ArrayDesc* find(Where w, std::string_view name) const {
    for (const ArrayDesc& a : arrays_)
      if (a.where == w && (name.empty() || a.name == name)) return &a;
    return nullptr;
  }

  Mesh build() {
    Mesh mesh;
    const ArrayDesc* pts = find(Where::Points, "");
    if (!pts) {
      if (num_points_ > 0) fail_line(piece_pos_, "<Piece> has no <Points> DataArray");
    } else {
      if (pts->components != 3)
        fail_line(pts->tag_pos, "Points have " + std::to_string(pts->components) + " components, expected 3");
      decode(*pts, 3 * num_points_, mesh.points);
      int64_t bad = io::vtk::first_non_finite(mesh.points);
      if (bad >= 0 && !io::lenient())
        fail_line(pts->tag_pos, "point " + std::to_string(bad / 3) + " has a non-finite coordinate (NaN or infinity)");
    }

    io::vtk::Cells cells;
    cells.offsets.assign(1, 0);
    const ArrayDesc* conn = find(Where::Cells, "connectivity");
    const ArrayDesc* offs = find(Where::Cells, "offsets");
    const ArrayDesc* types = find(Where::Cells, "types");
    size_t cells_pos = piece_pos_;
    if (num_cells_ > 0) {
      if (!conn || !offs || !types)
        fail_line(piece_pos_, std::string("<Cells> lacks the '") + (!conn ? "connectivity" : !offs ? "offsets" : "types") +
                                  "' DataArray");
      cells_pos = conn->tag_pos;
      std::vector<int64_t> ends;
      decode(*offs, num_cells_, ends);
      int64_t prev = 0;
      for (int64_t c = 0; c < num_cells_; ++c) {
        if (ends[size_t(c)] < prev)
          fail_line(offs->tag_pos, "offsets decrease (or are negative) at cell " + std::to_string(c));
        prev = ends[size_t(c)];
      }
      cells.offsets.insert(cells.offsets.end(), ends.begin(), ends.end());
      decode(*types, num_cells_, cells.types);
      decode(*conn, prev, cells.conn);
    }

    std::vector<RawArray> point_arrays, cell_arrays;
    for (const ArrayDesc& a : arrays_) {
      if (a.where != Where::PointData && a.where != Where::CellData) continue;
      RawArray r;
      r.name = a.name;
      r.components = a.components;
      r.integer = io::vtk::type_is_integer(a.type);
      int64_t n = a.where == Where::PointData ? num_points_ : num_cells_;
      decode(a, n * a.components, r.values);
      (a.where == Where::PointData ? point_arrays : cell_arrays).push_back(std::move(r));
    }
    io::vtk::assemble(mesh, notes_, cells, point_arrays, cell_arrays,
                      [&](const std::string& why) { fail_line(cells_pos, "Cells: " + why); });
    return mesh;
  }
};

// ---------------------------------------------------------------- writer

using Enc = WriteOptions::VtuEncoding;

class VtuWriter {
 public:
  explicit VtuWriter(Enc enc) : enc_(enc) {}

  template <class T>
  void array(const char* type, const std::string& name, int comps, const std::vector<T>& v) {
    xml_ += "        <DataArray type=\"";
    xml_ += type;
    xml_ += "\" Name=\"" + xml_escape(name) + "\"";
    if (comps != 1) xml_ += " NumberOfComponents=\"" + std::to_string(comps) + "\"";
    if (enc_ == Enc::Ascii) {
      xml_ += " format=\"ascii\">\n";
      for (size_t i = 0; i < v.size(); ++i) {
        if constexpr (std::is_floating_point_v<T>) io::append_double(xml_, v[i]);
        else io::append_int(xml_, int64_t(v[i]));
        xml_ += (i + 1) % size_t(comps == 1 ? 10 : comps) == 0 || i + 1 == v.size() ? '\n' : ' ';
      }
      xml_ += "        </DataArray>\n";
      return;
    }
    const uint64_t nbytes = v.size() * sizeof(T);
    if (enc_ == Enc::Base64) {
      // Header and data as one base64 stream (what VTK writes for uncompressed data).
      std::string block(sizeof nbytes + nbytes, '\0');
      std::memcpy(block.data(), &nbytes, sizeof nbytes);
      if (nbytes) std::memcpy(block.data() + sizeof nbytes, v.data(), nbytes);
      xml_ += " format=\"binary\">\n          ";
      xml_ += io::base64_encode(block);
      xml_ += "\n        </DataArray>\n";
      return;
    }
    xml_ += " format=\"appended\" offset=\"" + std::to_string(appended_.size()) + "\"/>\n";
    appended_.append(reinterpret_cast<const char*>(&nbytes), sizeof nbytes);
    if (nbytes) appended_.append(reinterpret_cast<const char*>(v.data()), nbytes);
  }

  std::string xml_;
  std::string appended_;

 private:
  Enc enc_;
};

}  // namespace

Mesh read_vtu(const std::string& path, ReadNotes& notes) {
  VtuReader r(path, notes);
  return r.read();
}

// Tets are the only cells written; triangles and edges would need values in every
// CellData array (labels and fields are per tet) and would confuse readers that take the
// label array as a per-tet material. Use Gmsh or Medit output to keep them.
void write_vtu(const std::string& path, const Mesh& mesh, const WriteOptions& options) {
  const int64_t nv = mesh.num_vertices(), nt = mesh.num_tets();
  VtuWriter w(options.vtu_encoding);
  std::string& x = w.xml_;
  x.reserve(options.vtu_encoding == Enc::Ascii ? size_t(nv) * 60 + size_t(nt) * 40 : 4096);
  if (options.vtu_encoding == Enc::Appended) w.appended_.reserve(size_t(nv) * 24 + size_t(nt) * 25 + 1024);
  x += "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"";
  x += io::vtk::kHostLittle ? "LittleEndian" : "BigEndian";
  x += "\" header_type=\"UInt64\">\n  <UnstructuredGrid>\n";
  x += "    <Piece NumberOfPoints=\"" + std::to_string(nv) + "\" NumberOfCells=\"" + std::to_string(nt) + "\">\n";
  if (!mesh.vertex_fields.empty()) {
    x += "      <PointData>\n";
    for (const Field& f : mesh.vertex_fields) w.array("Float64", f.name, f.components, f.values);
    x += "      </PointData>\n";
  }
  if (!mesh.tet_labels.empty() || !mesh.tet_fields.empty()) {
    x += "      <CellData>\n";
    for (const Labels& l : mesh.tet_labels) w.array("Int32", l.name, 1, l.values);
    for (const Field& f : mesh.tet_fields) w.array("Float64", f.name, f.components, f.values);
    x += "      </CellData>\n";
  }
  x += "      <Points>\n";
  w.array("Float64", "Points", 3, mesh.points);
  x += "      </Points>\n      <Cells>\n";
  // Connectivity is Int32: the mesh stores vertex indices as int32, so they always fit.
  w.array("Int32", "connectivity", 1, mesh.tets);
  std::vector<int64_t> offsets(static_cast<size_t>(nt));
  for (int64_t t = 0; t < nt; ++t) offsets[size_t(t)] = 4 * (t + 1);
  w.array("Int64", "offsets", 1, offsets);
  w.array("UInt8", "types", 1, std::vector<uint8_t>(size_t(nt), uint8_t(io::vtk::kTet)));
  x += "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n";

  io::AtomicFile file(path, true);
  if (options.vtu_encoding == Enc::Appended) {
    x += "  <AppendedData encoding=\"raw\">\n   _";
    file.write(x.data(), x.size());
    file.write(w.appended_.data(), w.appended_.size());
    const std::string tail = "\n  </AppendedData>\n</VTKFile>\n";
    file.write(tail.data(), tail.size());
  } else {
    x += "</VTKFile>\n";
    file.write(x.data(), x.size());
  }
  file.commit();
}

}  // namespace tc
