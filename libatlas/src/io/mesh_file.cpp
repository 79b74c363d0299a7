// Mesh files: OBJ and OFF parsed here (every error at file:line), PLY and STL
// through CGAL::IO after their headers are checked; writing through CGAL::IO.
#include "atlas/io/geometry_files.h"

#include "atlas/core/error.h"
#include "ply_header.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/IO/polygon_soup_io.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

namespace atlas::io {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_3;
using Polygon = std::vector<std::size_t>;

// PLY and STL go to CGAL's readers, which trust their headers (a property
// outside any element crashes the PLY reader; a count of 10^12 reserves
// memory for it): the header is checked here first, against the file's size.
uint64_t regular_file_size(const fs::path& file) {
    std::error_code ec;
    const auto st = std::filesystem::status(file, ec);
    if (ec || !std::filesystem::is_regular_file(st))
        throw Error(file.string() + ": cannot read mesh: not a regular file (a directory, device, FIFO or socket)");
    return std::filesystem::file_size(file, ec);
}

} // namespace

void detail::check_ply_header(const fs::path& file, bool need_faces) {
    const std::string f = file.string();
    const uint64_t size = regular_file_size(file);
    std::ifstream in(file, std::ios::binary);
    std::string line;
    size_t line_no = 0;
    uint64_t header_bytes = 0;
    auto fail = [&](const std::string& why) -> void { throw Error(f + ":" + std::to_string(line_no) + ": PLY header: " + why); };
    auto next = [&]() {
        if (!std::getline(in, line)) {
            ++line_no;
            fail("ends before 'end_header'");
        }
        ++line_no;
        header_bytes += line.size() + 1;
        if (header_bytes > 65536) fail("longer than 64 KiB");
        if (!line.empty() && line.back() == '\r') line.pop_back();
    };
    auto words = [&]() {
        std::vector<std::string> w;
        size_t i = 0;
        while (i < line.size()) {
            while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
            const size_t b = i;
            while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
            if (i > b) w.push_back(line.substr(b, i - b));
        }
        return w;
    };
    next();
    if (line != "ply") fail("the file does not start with 'ply'");
    next();
    auto w = words();
    if (w.size() != 3 || w[0] != "format" || (w[1] != "ascii" && w[1] != "binary_little_endian" && w[1] != "binary_big_endian"))
        fail("expected 'format ascii|binary_little_endian|binary_big_endian 1.0'");
    const bool ascii = w[1] == "ascii", binary_big_endian = w[1] == "binary_big_endian";
    // The scalar types PLY names, with their size in a binary body (0: not a PLY type).
    auto scalar_size = [](const std::string& t) -> size_t {
        if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
        if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
        if (t == "int" || t == "uint" || t == "float" || t == "int32" || t == "uint32" || t == "float32") return 4;
        if (t == "double" || t == "float64") return 8;
        return 0;
    };
    auto is_scalar = [&](const std::string& t) { return scalar_size(t) != 0; };
    struct Element {
        std::string name;
        uint64_t count = 0;
        std::vector<std::string> props, types; // types: the scalar type, or "list COUNT_TYPE ITEM_TYPE"
        bool has_list = false;
    };
    std::vector<Element> elements;
    while (true) {
        next();
        w = words();
        if (w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
        if (w[0] == "end_header") break;
        if (w[0] == "element") {
            uint64_t n = 0;
            const auto r = w.size() == 3 ? std::from_chars(w[2].data(), w[2].data() + w[2].size(), n) : std::from_chars_result{nullptr, std::errc::invalid_argument};
            if (w.size() != 3 || r.ec != std::errc() || r.ptr != w[2].data() + w[2].size()) fail("expected 'element NAME COUNT'");
            elements.push_back({w[1], n, {}, {}, false});
        } else if (w[0] == "property") {
            if (elements.empty()) fail("a property before any element");
            if (w.size() == 5 && w[1] == "list") {
                if (!is_scalar(w[2]) || !is_scalar(w[3])) fail("unknown list types '" + w[2] + "', '" + w[3] + "'");
                elements.back().has_list = true;
                elements.back().props.push_back(w[4]);
                elements.back().types.push_back("list " + w[2] + " " + w[3]);
            } else if (w.size() == 3 && is_scalar(w[1])) {
                elements.back().props.push_back(w[2]);
                elements.back().types.push_back(w[1]);
            } else {
                fail("expected 'property TYPE NAME' or 'property list COUNT_TYPE INDEX_TYPE NAME'");
            }
        } else {
            fail("unknown keyword '" + w[0].substr(0, 40) + "'");
        }
    }
    const Element* vertex = nullptr;
    const Element* face = nullptr;
    for (const auto& e : elements) {
        if (e.props.empty()) throw Error(f + ": PLY header: element '" + e.name + "' has no properties");
        // CGAL's readers act on each element of a name; the checks below see one.
        if ((e.name == "vertex" && vertex) || (e.name == "face" && face))
            throw Error(f + ": PLY header: element '" + e.name + "' is declared twice");
        if (e.name == "vertex") vertex = &e;
        if (e.name == "face") face = &e;
    }
    if (!vertex) throw Error(f + ": PLY header: no 'vertex' element");
    for (const char* axis : {"x", "y", "z"})
        if (std::find(vertex->props.begin(), vertex->props.end(), axis) == vertex->props.end())
            throw Error(f + ": PLY header: the vertex element has no property '" + axis + "'");
    // CGAL's readers take the coordinates (and normals) as float or double only, all of
    // one type for point sets; any other type reaches a null pointer inside CGAL.
    std::string coordinate_type;
    for (size_t i = 0; i < vertex->props.size(); ++i) {
        const std::string& name = vertex->props[i];
        if (name != "x" && name != "y" && name != "z" && name != "nx" && name != "ny" && name != "nz") continue;
        const std::string& t = vertex->types[i];
        const std::string kind = t == "float" || t == "float32" ? "float" : t == "double" || t == "float64" ? "double" : "";
        if (kind.empty() || (!coordinate_type.empty() && kind != coordinate_type))
            throw Error(f + ": PLY header: the vertex property '" + name + "' is " + (t.rfind("list", 0) == 0 ? "a list" : t) +
                        "; expected x, y, z (and nx, ny, nz) all float or all double");
        coordinate_type = kind;
    }
    if (need_faces && (!face || !face->has_list)) throw Error(f + ": PLY header: no 'face' element with a list of vertex indices");
    // Every property takes at least one byte (binary) or two (ascii: a digit
    // and a separator): counts the file cannot hold are refused.
    const uint64_t body = size > header_bytes ? size - header_bytes : 0;
    uint64_t least = 0;
    for (const auto& e : elements) {
        const uint64_t per = uint64_t(e.props.size()) * (ascii ? 2 : 1);
        if (e.count > body / per + 1) throw Error(f + ": PLY header: element '" + e.name + "' claims " + std::to_string(e.count) +
                                                      " entries, more than the file's " + std::to_string(body) + " bytes after the header hold");
        least += e.count * per;
    }
    if (least > body + 1) throw Error(f + ": PLY header: the elements need at least " + std::to_string(least) + " bytes, the file has " + std::to_string(body) + " after the header");

    // The lists' lengths are in the body, and CGAL sizes each list by its length before
    // reading it (a length of 2^31 asked for 7 GB): every length must fit in what is left
    // of the file, at least one byte per item (binary) or two (ascii). A body that ends
    // before a list's length is refused too: CGAL does not check that read, and sized the
    // list from the bytes it half-read (2.9 GB for a file of 220 bytes; sanitized fuzz run).
    if (std::none_of(elements.begin(), elements.end(), [](const Element& e) { return e.has_list; })) return;
    in.clear();
    in.seekg(std::streamoff(header_bytes));
    uint64_t pos = header_bytes; // binary: the body offset
    std::string tok;             // ascii: the current word
    auto skip = [&](uint64_t n, size_t item_size) -> bool {
        if (!ascii) {
            pos += n * item_size;
            return bool(in.seekg(std::streamoff(pos)));
        }
        for (uint64_t i = 0; i < n; ++i)
            if (!(in >> tok)) return false;
        return true;
    };
    // A list's length, as a double (negative or NaN when the file says so); false at the end.
    auto list_length = [&](const std::string& count_type, double& n) -> bool {
        if (ascii) {
            if (!(in >> tok)) return false;
            n = std::strtod(tok.c_str(), nullptr);
            return true;
        }
        const size_t cs = scalar_size(count_type);
        unsigned char b[8] = {};
        if (!in.read(reinterpret_cast<char*>(b), std::streamsize(cs))) return false;
        pos += cs;
        if (binary_big_endian) std::reverse(b, b + cs);
        if (count_type == "float" || count_type == "float32") {
            float v;
            std::memcpy(&v, b, 4);
            n = v;
        } else if (count_type == "double" || count_type == "float64") {
            std::memcpy(&n, b, 8);
        } else {
            uint64_t u = 0;
            std::memcpy(&u, b, cs); // little-endian host (x86-64, the supported platform)
            const bool is_signed = count_type == "char" || count_type == "int8" || count_type == "short" || count_type == "int16" ||
                                   count_type == "int" || count_type == "int32";
            n = is_signed && ((u >> (8 * cs - 1)) & 1) ? -1.0 : double(u);
        }
        return true;
    };
    auto ends_early = [&](const Element& e, uint64_t k) {
        throw Error(f + ": PLY body: the file ends in element '" + e.name + "' entry " + std::to_string(k) + " (expected " + std::to_string(e.count) +
                    " entries)");
    };
    for (const Element& e : elements) {
        if (!e.has_list) { // fixed size: skipped whole (a file that ends here stops the scan: no list is sized from it)
            uint64_t entry = 0;
            for (const auto& t : e.types) entry += scalar_size(t);
            if (!(ascii ? skip(e.count * e.props.size(), 1) : skip(e.count, entry))) return;
            continue;
        }
        for (uint64_t k = 0; k < e.count; ++k)
            for (const auto& t : e.types) {
                if (t.rfind("list ", 0) != 0) { // a scalar
                    if (!skip(1, scalar_size(t))) ends_early(e, k);
                    continue;
                }
                const size_t sp = t.find(' ', 5);
                const std::string count_type = t.substr(5, sp - 5), item_type = t.substr(sp + 1);
                double n = 0;
                if (!list_length(count_type, n)) ends_early(e, k);
                const uint64_t at = ascii ? uint64_t(in.tellg()) : pos, left = size > at ? size - at : 0;
                const double most = ascii ? double(left) / 2 + 1 : double(left / scalar_size(item_type));
                if (!(n >= 0))
                    throw Error(f + ": PLY body: element '" + e.name + "' entry " + std::to_string(k) + " has a list of " +
                                (std::isfinite(n) ? std::string("a negative number of") : std::string("a non-finite number of")) +
                                " items (a list length is a count from 0)");
                if (n > most)
                    throw Error(f + ": PLY body: element '" + e.name + "' entry " + std::to_string(k) + " has a list of " +
                                (std::isfinite(n) ? std::to_string(int64_t(std::min(n, 9e18))) : std::string("a non-finite number of")) +
                                " items, more than the rest of the file holds");
                if (!skip(uint64_t(n), scalar_size(item_type))) ends_early(e, k);
            }
    }
}

namespace {
void check_stl(const fs::path& file) {
    const uint64_t size = regular_file_size(file);
    std::ifstream in(file, std::ios::binary);
    char head[84] = {};
    in.read(head, 84);
    const bool ascii = std::string(head, std::min<size_t>(size_t(in.gcount()), 5)) == "solid";
    if (size < 84) {
        if (!ascii) throw Error(file.string() + ": STL file of " + std::to_string(size) + " bytes: too short for a binary STL header");
        return;
    }
    uint32_t n = 0;
    std::memcpy(&n, head + 80, 4);
    // A binary file says how many 50-byte triangles follow; ASCII files may start with "solid" too.
    if (84 + 50ull * n == size) return;
    if (!ascii) throw Error(file.string() + ": binary STL claims " + std::to_string(n) + " triangles (" + std::to_string(84 + 50ull * n) +
                            " bytes), the file has " + std::to_string(size));
}

// Text OBJ and OFF are parsed here (not by CGAL) so that every error names
// file:line, the vertex or face, and what was expected; CGAL's readers accept
// truncated files silently.
struct TextReader {
    std::string file;
    std::ifstream in;
    std::string line;
    size_t line_no = 0;

    explicit TextReader(const fs::path& f) : file(f.string()), in(f) {
        if (!in) throw Error(file + ": cannot open mesh file");
    }
    // Next line split into tokens, '#' comments removed; false at the end.
    bool next(std::vector<std::string>& tok) {
        while (std::getline(in, line)) {
            ++line_no;
            if (const size_t h = line.find('#'); h != std::string::npos) line.resize(h);
            tok.clear();
            size_t i = 0;
            while (i < line.size()) {
                while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
                size_t j = i;
                while (j < line.size() && !std::isspace(static_cast<unsigned char>(line[j]))) ++j;
                if (j > i) tok.push_back(line.substr(i, j - i));
                i = j;
            }
            if (!tok.empty()) return true;
        }
        return false;
    }
    [[noreturn]] void fail(const std::string& what) const { throw Error(file + ":" + std::to_string(line_no) + ": " + what); }
    double real(const std::string& t, const std::string& what) const {
        double v = 0;
        const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
        if (r.ec != std::errc() || r.ptr != t.data() + t.size()) fail(what + ": expected a number, got '" + t + "'");
        return v;
    }
    long long integer(const std::string& t, const std::string& what) const {
        long long v = 0;
        const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
        if (r.ec != std::errc() || r.ptr != t.data() + t.size()) fail(what + ": expected an integer, got '" + t + "'");
        return v;
    }
    Point vertex(const std::vector<std::string>& tok, size_t first, const std::string& what) const {
        double c[3];
        for (int a = 0; a < 3; ++a) {
            c[a] = real(tok[first + size_t(a)], what);
            if (!std::isfinite(c[a])) fail(what + ": " + "xyz"[a] + " is not finite ('" + tok[first + size_t(a)] + "')");
            if (std::abs(c[a]) > kMaxMeshCoordinate)
                fail(what + ": " + "xyz"[a] + " = " + tok[first + size_t(a)] + " is outside the supported range +-1e18 m");
        }
        return Point(c[0], c[1], c[2]);
    }
};

void read_obj(const fs::path& f, std::vector<Point>& points, std::vector<Polygon>& polys) {
    TextReader r(f);
    std::vector<std::string> tok;
    struct Pending {
        size_t line, face;
        size_t corner;
        long long index; // 1-based as written
    };
    std::vector<Pending> forward; // positive indices checked once all vertices are known
    while (r.next(tok)) {
        const std::string& k = tok[0];
        if (k == "v") {
            const std::string what = "vertex " + std::to_string(points.size() + 1);
            if (tok.size() < 4) r.fail(what + ": expected 'v x y z', got " + std::to_string(tok.size() - 1) + " coordinate(s)");
            points.push_back(r.vertex(tok, 1, what));
        } else if (k == "vn" || k == "vt" || k == "vp") {
            const size_t need = k == "vn" ? 3 : 1;
            if (tok.size() < need + 1) r.fail("'" + k + "': expected " + std::to_string(need) + " number(s), got " + std::to_string(tok.size() - 1));
            for (size_t i = 1; i < tok.size(); ++i) r.real(tok[i], "'" + k + "'");
        } else if (k == "f") {
            const std::string what = "face " + std::to_string(polys.size() + 1);
            if (tok.size() < 4)
                r.fail(what + ": expected at least 3 corners 'f v1 v2 v3', got " + std::to_string(tok.size() - 1));
            Polygon poly;
            for (size_t i = 1; i < tok.size(); ++i) {
                const std::string& t = tok[i];
                const std::string corner = what + " corner " + std::to_string(i);
                // v, v/vt, v//vn or v/vt/vn
                const size_t s1 = t.find('/');
                const std::string vs = t.substr(0, s1);
                if (s1 != std::string::npos) {
                    const std::string rest = t.substr(s1 + 1);
                    const size_t s2 = rest.find('/');
                    const std::string vt = rest.substr(0, s2), vn = s2 == std::string::npos ? std::string() : rest.substr(s2 + 1);
                    if ((vt.empty() && s2 == std::string::npos) || (s2 != std::string::npos && vn.empty()) ||
                        (vn.find('/') != std::string::npos))
                        r.fail(corner + ": expected v, v/vt, v//vn or v/vt/vn, got '" + t + "'");
                    if (!vt.empty()) r.integer(vt, corner);
                    if (!vn.empty()) r.integer(vn, corner);
                }
                const long long v = r.integer(vs, corner);
                if (v == 0) r.fail(corner + ": vertex index 0 (OBJ counts from 1)");
                if (v < 0) {
                    if (-v > static_cast<long long>(points.size()))
                        r.fail(corner + ": relative vertex index " + std::to_string(v) + " but only " + std::to_string(points.size()) +
                               " vertices precede this line");
                    poly.push_back(size_t(static_cast<long long>(points.size()) + v));
                } else {
                    forward.push_back({r.line_no, polys.size() + 1, i, v});
                    poly.push_back(size_t(v - 1));
                }
            }
            polys.push_back(std::move(poly));
        }
        // Other statements (g, o, s, usemtl, mtllib, l, p, ...) carry no geometry we use.
    }
    if (r.in.bad()) throw Error(r.file + ": read error after line " + std::to_string(r.line_no));
    for (const Pending& p : forward)
        if (size_t(p.index) > points.size())
            throw Error(r.file + ":" + std::to_string(p.line) + ": face " + std::to_string(p.face) + " corner " + std::to_string(p.corner) +
                        " uses vertex " + std::to_string(p.index) + " but the file has " + std::to_string(points.size()) +
                        " vertices (1.." + std::to_string(points.size()) + "); truncated file?");
}

void read_off(const fs::path& f, std::vector<Point>& points, std::vector<Polygon>& polys) {
    TextReader r(f);
    std::vector<std::string> tok;
    if (!r.next(tok)) throw Error(r.file + ": empty file, expected an OFF header");
    const std::string head = tok[0];
    static const char* kHeads[] = {"OFF", "COFF", "NOFF", "CNOFF", "STOFF", "STCOFF", "STNOFF", "STCNOFF"};
    if (std::find(std::begin(kHeads), std::end(kHeads), head) == std::end(kHeads))
        r.fail("expected an OFF header (OFF, COFF, NOFF, ...), got '" + head + "'");
    tok.erase(tok.begin());
    if (tok.empty() && !r.next(tok)) r.fail("expected the counts 'vertices faces edges' after the header");
    const size_t counts_line = r.line_no;
    if (tok.size() < 2) r.fail("expected the counts 'vertices faces edges', got '" + r.line + "'");
    const long long nv = r.integer(tok[0], "vertex count"), nf = r.integer(tok[1], "face count");
    if (nv < 0 || nf < 0) r.fail("negative vertex or face count");
    points.reserve(size_t(std::min(nv, 1LL << 26)));
    for (long long i = 0; i < nv; ++i) {
        const std::string what = "vertex " + std::to_string(i);
        if (!r.next(tok))
            throw Error(r.file + ": truncated: line " + std::to_string(counts_line) + " announces " + std::to_string(nv) +
                        " vertices, the file ends after " + std::to_string(i) + " (at " + what + ")");
        if (tok.size() < 3) r.fail(what + ": expected 'x y z', got " + std::to_string(tok.size()) + " number(s)");
        points.push_back(r.vertex(tok, 0, what));
    }
    for (long long i = 0; i < nf; ++i) {
        const std::string what = "face " + std::to_string(i);
        if (!r.next(tok))
            throw Error(r.file + ": truncated: line " + std::to_string(counts_line) + " announces " + std::to_string(nf) +
                        " faces, the file ends after " + std::to_string(i) + " (at " + what + ")");
        const long long n = r.integer(tok[0], what + " corner count");
        if (n < 3) r.fail(what + ": expected at least 3 corners, got " + std::to_string(n));
        if (static_cast<long long>(tok.size()) < n + 1)
            r.fail(what + ": announces " + std::to_string(n) + " corners but lists " + std::to_string(tok.size() - 1) + "; truncated?");
        Polygon poly;
        for (long long c = 0; c < n; ++c) {
            const long long v = r.integer(tok[size_t(c + 1)], what + " corner " + std::to_string(c));
            if (v < 0 || v >= nv)
                r.fail(what + " corner " + std::to_string(c) + " uses vertex " + std::to_string(v) + " but the file has " + std::to_string(nv) +
                       " vertices (0.." + std::to_string(nv - 1) + ")");
            poly.push_back(size_t(v));
        }
        polys.push_back(std::move(poly)); // tokens after the corners: an optional colour
    }
    if (r.in.bad()) throw Error(r.file + ": read error after line " + std::to_string(r.line_no));
}

} // namespace

PolygonSoup read_polygon_soup(const fs::path& file) {
    std::vector<Point> points;
    std::vector<Polygon> polys;
    if (!fs::exists(file)) throw Error(file.string() + ": no such mesh file");
    regular_file_size(file); // a device or FIFO never ends: refused before reading
    std::string ext = file.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    if (ext == ".obj") read_obj(file, points, polys);
    else if (ext == ".off") read_off(file, points, polys);
    else {
        if (ext == ".ply") detail::check_ply_header(file, true);
        else if (ext == ".stl") check_stl(file);
        bool ok = false;
        try {
            ok = CGAL::IO::read_polygon_soup(file.string(), points, polys, CGAL::parameters::verbose(false));
        } catch (const std::exception& e) {
            throw Error(file.string() + ": cannot read mesh (" + e.what() + ")");
        }
        if (!ok) throw Error(file.string() + ": cannot read mesh (expected OBJ, OFF, PLY or STL)");
    }
    if (polys.empty()) throw Error(file.string() + ": the mesh has no faces");
    PolygonSoup soup;
    soup.points.reserve(points.size());
    for (const Point& p : points) soup.points.push_back({{p.x(), p.y(), p.z()}});
    soup.polygons = std::move(polys);
    validate_polygon_soup(soup, file.string()); // CGAL's readers check neither values nor indices
    return soup;
}

void write_mesh(const fs::path& file, const Mesh& m) {
    std::vector<Point> points;
    for (const Vec3f& v : m.vertices) points.emplace_back(v[0], v[1], v[2]);
    std::vector<Polygon> polys;
    for (const auto& t : m.triangles) polys.push_back({t[0], t[1], t[2]});
    if (!CGAL::IO::write_polygon_soup(file.string(), points, polys, CGAL::parameters::stream_precision(9)))
        throw Error(file.string() + ": cannot write mesh");
}

} // namespace atlas::io
