// Point cloud files: PLY through CGAL (after its header is checked), XYZ text here.
#include "atlas/io/geometry_files.h"

#include "atlas/core/error.h"
#include "ply_header.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Point_set_3.h>
#include <CGAL/Point_set_3/IO.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <sstream>

namespace atlas::io {
namespace {

Points read_xyz(const fs::path& file) {
    std::ifstream in(file);
    if (!in) throw Error(file.string() + ": cannot open point file");
    Points pts;
    std::vector<float> radius, weight;
    std::string line;
    int line_no = 0;
    size_t columns = 0;
    while (std::getline(in, line)) {
        ++line_no;
        if (auto hash = line.find('#'); hash != std::string::npos) line.resize(hash);
        std::istringstream ss(line);
        std::vector<double> v;
        std::string tok;
        while (ss >> tok) {
            char* end = nullptr;
            const double d = std::strtod(tok.c_str(), &end);
            if (end == tok.c_str() || *end != '\0' || !std::isfinite(d))
                throw Error(file.string() + ":" + std::to_string(line_no) + ": expected a finite number, got '" + tok + "'");
            v.push_back(d);
        }
        if (v.empty()) continue;
        if (v.size() < 3 || v.size() > 5)
            throw Error(file.string() + ":" + std::to_string(line_no) + ": expected 'x y z [radius [weight]]', got " + std::to_string(v.size()) + " numbers");
        if (columns == 0) columns = v.size();
        if (v.size() != columns)
            throw Error(file.string() + ":" + std::to_string(line_no) + ": " + std::to_string(v.size()) + " columns, earlier lines had " + std::to_string(columns));
        pts.positions.push_back({{float(v[0]), float(v[1]), float(v[2])}});
        if (columns >= 4) radius.push_back(float(v[3]));
        if (columns >= 5) weight.push_back(float(v[4]));
    }
    if (columns >= 4) pts.attributes["radius"] = std::move(radius);
    if (columns >= 5) pts.attributes["weight"] = std::move(weight);
    return pts;
}

Points read_ply(const fs::path& file) {
    using K = CGAL::Exact_predicates_inexact_constructions_kernel;
    CGAL::Point_set_3<K::Point_3> ps;
    std::ifstream in(file, std::ios::binary);
    if (!in) throw Error(file.string() + ": cannot open point file");
    if (!CGAL::IO::read_PLY(in, ps)) throw Error(file.string() + ": cannot read PLY point cloud");
    Points pts;
    pts.positions.reserve(ps.size());
    size_t i = 0;
    for (auto it = ps.begin(); it != ps.end(); ++it, ++i) {
        const auto& p = ps.point(*it);
        if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z()))
            throw Error(file.string() + ": point " + std::to_string(i) + " is not finite");
        pts.positions.push_back({{float(p.x()), float(p.y()), float(p.z())}});
    }
    for (const std::string& name : ps.properties()) {
        if (name == "point" || name == "index" || name == "normal") continue;
        std::vector<float> values;
        values.reserve(ps.size());
        if (auto [fm, ok] = ps.template property_map<float>(name); ok) {
            for (auto it = ps.begin(); it != ps.end(); ++it) values.push_back(fm[*it]);
        } else if (auto [dm, okd] = ps.template property_map<double>(name); okd) {
            for (auto it = ps.begin(); it != ps.end(); ++it) values.push_back(float(dm[*it]));
        } else {
            continue; // integer and colour properties are not attributes
        }
        pts.attributes[name] = std::move(values);
    }
    return pts;
}

} // namespace

Points read_points(const fs::path& file) {
    if (!fs::exists(file)) throw Error(file.string() + ": no such point file");
    if (!fs::is_regular_file(file))
        throw Error(file.string() + ": cannot read points: not a regular file (a directory, device, FIFO or socket)");
    std::string ext = file.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    if (ext == ".ply") {
        detail::check_ply_header(file, false); // CGAL's reader trusts the header
        return read_ply(file);
    }
    if (ext == ".xyz" || ext == ".txt" || ext == ".pts") return read_xyz(file);
    throw Error(file.string() + ": unknown point file type (expected .ply or .xyz)");
}

} // namespace atlas::io
