// Fields as NumPy arrays without a copy: each channel is a read-only view of
// the field's own memory whose base object keeps the (immutable) field alive.
#include "bindings.h"

#include "atlas/core/files.h"
#include "atlas/core/memory.h"
#include "atlas/io/writers.h"

#include <algorithm>
#include <cstring>

namespace atlas::python {

namespace {

// Holds a value alive for as long as a NumPy array looks at its memory.
template <typename Ptr>
py::capsule keep_alive(Ptr p) {
    auto* holder = new Ptr(std::move(p));
    return py::capsule(holder, [](void* q) { delete static_cast<Ptr*>(q); });
}

template <typename Ptr>
py::array readonly_view(const Ptr& owner, const float* data, std::vector<py::ssize_t> shape) {
    std::vector<py::ssize_t> strides(shape.size());
    py::ssize_t s = sizeof(float);
    for (size_t i = shape.size(); i-- > 0;) {
        strides[i] = s;
        s *= shape[i];
    }
    py::array a(py::dtype::of<float>(), shape, strides, data, keep_alive(owner));
    a.attr("setflags")(py::arg("write") = false);
    return a;
}

// A field written to one file in a graph output's format (by the extension unless
// given), atomically: a failed write leaves no file.
void write_field(const Value& v, const py::object& path, const py::object& format) {
    const std::filesystem::path p = py::str(path).cast<std::string>();
    const std::string fmt = format.is_none() ? io::output_format_for_path(p) : format.cast<std::string>();
    py::gil_scoped_release nogil;
    write_file_atomic(p, [&](const std::filesystem::path& tmp) { io::write_value(v, tmp, fmt, {}); });
}

struct PyField2D {
    Field2DPtr f;
};
struct PyField3D {
    Field3DPtr f;
};

template <typename F>
int channel_index(const F& f, const py::handle& key) {
    if (py::isinstance<py::str>(key)) {
        std::string name = key.cast<std::string>();
        int c = f.find_channel(name);
        if (c < 0) {
            std::string known;
            for (const auto& n : f.channel_names()) known += (known.empty() ? "" : ", ") + n;
            throw py::key_error("no channel '" + name + "' (channels: " + known + ")");
        }
        return c;
    }
    int c = key.cast<int>();
    if (c < 0) c += f.channels();
    if (c < 0 || c >= f.channels()) throw py::index_error("channel " + std::to_string(c) + " out of range");
    return c;
}

py::tuple vec_tuple(const Vec2d& v) { return py::make_tuple(v[0], v[1]); }
py::tuple vec_tuple(const Vec3d& v) { return py::make_tuple(v[0], v[1], v[2]); }

template <int N>
Box<N> box_from_python(const py::handle& o) {
    auto seq = o.cast<std::vector<std::vector<double>>>();
    if (seq.size() != 2 || seq[0].size() != size_t(N) || seq[1].size() != size_t(N))
        throw py::value_error("bounds must be ((min...), (max...)) with " + std::to_string(N) + " values each");
    Box<N> b;
    for (int i = 0; i < N; ++i) {
        b.min[i] = seq[0][size_t(i)];
        b.max[i] = seq[1][size_t(i)];
    }
    return b;
}

template <typename F>
void copy_channels(F& f, const py::array_t<float, py::array::c_style | py::array::forcecast>& a, size_t per_channel) {
    const float* src = a.data();
    for (int c = 0; c < f.channels(); ++c)
        std::memcpy(f.channel(c).data(), src + size_t(c) * per_channel, per_channel * sizeof(float));
}

} // namespace

Value field_from_array(const py::array& array, int dims, const py::object& bounds, const py::object& channel_names,
                       const MemoryBudget* budget) {
    auto a = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(array);
    if (!a) throw py::type_error("expected a NumPy array of numbers");
    const auto nd = a.ndim();
    if (dims == 0) dims = nd == 2 ? 2 : 3;
    const bool has_channels = dims == 2 ? nd == 3 : nd == 4;
    if (nd != (dims == 2 ? 2 : 3) + (has_channels ? 1 : 0))
        throw py::value_error("a " + std::to_string(dims) + "D field is an array of shape " +
                              (dims == 2 ? "(ny, nx) or (channels, ny, nx)" : "(nz, ny, nx) or (channels, nz, ny, nx)") +
                              ", got " + std::to_string(nd) + " dimensions");
    const int channels = has_channels ? int(a.shape(0)) : 1;
    std::vector<std::string> names;
    if (!channel_names.is_none()) names = channel_names.cast<std::vector<std::string>>();
    if (!names.empty() && int(names.size()) != channels)
        throw py::value_error("channel_names has " + std::to_string(names.size()) + " names for " +
                              std::to_string(channels) + " channels");
    const int o = has_channels ? 1 : 0;
    if (bounds.is_none())
        throw py::value_error("a field needs world bounds: bounds=((min...), (max...)) in metres");
    if (dims == 2) {
        Vec2i res{{int(a.shape(o + 1)), int(a.shape(o))}};
        auto f = std::make_shared<Field2D>(res, channels, box_from_python<2>(bounds), names, budget);
        copy_channels(*f, a, f->voxel_count());
        return Field2DPtr(f);
    }
    Vec3i res{{int(a.shape(o + 2)), int(a.shape(o + 1)), int(a.shape(o))}};
    auto f = std::make_shared<Field3D>(res, channels, box_from_python<3>(bounds), names, budget);
    copy_channels(*f, a, f->voxel_count());
    return Field3DPtr(f);
}

py::object value_to_python(const Value& v) {
    if (auto* p = std::get_if<Field3DPtr>(&v)) return py::cast(PyField3D{*p});
    if (auto* p = std::get_if<Field2DPtr>(&v)) return py::cast(PyField2D{*p});
    if (auto* p = std::get_if<MeshPtr>(&v)) {
        const MeshPtr& m = *p;
        py::dict d;
        d["vertices"] = readonly_view(m, reinterpret_cast<const float*>(m->vertices.data()),
                                      {py::ssize_t(m->vertices.size()), 3});
        py::array tri(py::dtype::of<uint32_t>(), {py::ssize_t(m->triangles.size()), py::ssize_t(3)},
                      reinterpret_cast<const uint32_t*>(m->triangles.data()), keep_alive(m));
        tri.attr("setflags")(py::arg("write") = false);
        d["triangles"] = tri;
        return d;
    }
    if (auto* p = std::get_if<PointsPtr>(&v)) {
        const PointsPtr& pts = *p;
        py::dict d, attrs;
        d["positions"] = readonly_view(pts, reinterpret_cast<const float*>(pts->positions.data()),
                                       {py::ssize_t(pts->positions.size()), 3});
        for (const auto& [name, values] : pts->attributes)
            attrs[py::str(name)] = readonly_view(pts, values.data(), {py::ssize_t(values.size())});
        d["attributes"] = attrs;
        return d;
    }
    return py::none();
}

Value python_to_value(const py::handle& o) {
    if (py::isinstance<PyField3D>(o)) return o.cast<const PyField3D&>().f;
    if (py::isinstance<PyField2D>(o)) return o.cast<const PyField2D&>().f;
    return {};
}

void bind_fields(py::module_& m) {
    static_assert(sizeof(Vec3f) == 3 * sizeof(float), "Vec3f arrays are viewed as (n, 3) floats");

    py::class_<PyField3D>(m, "Field3D", R"doc(
An immutable 3D field: float channels over a world box (metres), cell-centred.
field["name"] or field[i] is one channel as a read-only NumPy array of shape
(nz, ny, nx) that shares the field's memory (no copy) and keeps it alive.)doc")
        .def(py::init([](const py::array& array, const py::object& bounds, const py::object& channel_names) {
                 return PyField3D{std::get<Field3DPtr>(field_from_array(array, 3, bounds, channel_names, nullptr))};
             }),
             py::arg("array"), py::arg("bounds"), py::arg("channel_names") = py::none(),
             "A new field (a copy of `array`, shape (nz, ny, nx) or (channels, nz, ny, nx)).")
        .def_property_readonly("resolution", [](const PyField3D& s) { return py::make_tuple(s.f->nx(), s.f->ny(), s.f->nz()); },
                               "(nx, ny, nz) voxels")
        .def_property_readonly("shape", [](const PyField3D& s) { return py::make_tuple(s.f->nz(), s.f->ny(), s.f->nx()); },
                               "(nz, ny, nx): the shape of each channel's array (x fastest)")
        .def_property_readonly("bounds", [](const PyField3D& s) { return py::make_tuple(vec_tuple(s.f->bounds().min), vec_tuple(s.f->bounds().max)); },
                               "((xmin, ymin, zmin), (xmax, ymax, zmax)) in metres")
        .def_property_readonly("voxel_size", [](const PyField3D& s) { return vec_tuple(s.f->voxel_size()); }, "metres")
        .def_property_readonly("channels", [](const PyField3D& s) { return s.f->channels(); })
        .def_property_readonly("channel_names", [](const PyField3D& s) { return s.f->channel_names(); })
        .def("channel", [](const PyField3D& s, const py::handle& key) {
                int c = channel_index(*s.f, key);
                return readonly_view(s.f, s.f->channel(c).data(), {s.f->nz(), s.f->ny(), s.f->nx()});
            }, py::arg("key"), "One channel (by index or name) as a read-only array sharing the field's memory.")
        .def("__getitem__", [](const PyField3D& s, const py::handle& key) {
                int c = channel_index(*s.f, key);
                return readonly_view(s.f, s.f->channel(c).data(), {s.f->nz(), s.f->ny(), s.f->nx()});
            })
        .def("__len__", [](const PyField3D& s) { return s.f->channels(); })
        .def("to_numpy", [](const PyField3D& s) {
                py::array_t<float> a({py::ssize_t(s.f->channels()), py::ssize_t(s.f->nz()), py::ssize_t(s.f->ny()), py::ssize_t(s.f->nx())});
                for (int c = 0; c < s.f->channels(); ++c)
                    std::memcpy(a.mutable_data(c), s.f->channel(c).data(), s.f->voxel_count() * sizeof(float));
                return a;
            }, "A writable copy of all channels, shape (channels, nz, ny, nx).")
        .def("write", [](const PyField3D& s, const py::object& path, const py::object& format) { write_field(Value(s.f), path, format); },
             py::arg("path"), py::arg("format") = py::none(),
             "Writes the field to one file as a graph output would (format from the extension: vdb, exr, ...; or given), atomically.")
        .def("__eq__", [](const PyField3D& a, const PyField3D& b) { return a.f == b.f || *a.f == *b.f; })
        .def("__repr__", [](const PyField3D& s) {
            return "<atlas.Field3D " + std::to_string(s.f->nx()) + "x" + std::to_string(s.f->ny()) + "x" +
                   std::to_string(s.f->nz()) + ", " + std::to_string(s.f->channels()) + " channel(s)>";
        });

    py::class_<PyField2D>(m, "Field2D", R"doc(
An immutable 2D field (an NDF over the world's x, y): float channels over a
world box (metres). field["name"] or field[i] is one channel as a read-only
NumPy array of shape (ny, nx) sharing the field's memory.)doc")
        .def(py::init([](const py::array& array, const py::object& bounds, const py::object& channel_names) {
                 return PyField2D{std::get<Field2DPtr>(field_from_array(array, 2, bounds, channel_names, nullptr))};
             }),
             py::arg("array"), py::arg("bounds"), py::arg("channel_names") = py::none(),
             "A new field (a copy of `array`, shape (ny, nx) or (channels, ny, nx)).")
        .def_property_readonly("resolution", [](const PyField2D& s) { return py::make_tuple(s.f->width(), s.f->height()); }, "(nx, ny)")
        .def_property_readonly("shape", [](const PyField2D& s) { return py::make_tuple(s.f->height(), s.f->width()); }, "(ny, nx)")
        .def_property_readonly("bounds", [](const PyField2D& s) { return py::make_tuple(vec_tuple(s.f->bounds().min), vec_tuple(s.f->bounds().max)); },
                               "((xmin, ymin), (xmax, ymax)) in metres")
        .def_property_readonly("voxel_size", [](const PyField2D& s) { return vec_tuple(s.f->voxel_size()); }, "metres")
        .def_property_readonly("channels", [](const PyField2D& s) { return s.f->channels(); })
        .def_property_readonly("channel_names", [](const PyField2D& s) { return s.f->channel_names(); })
        .def("channel", [](const PyField2D& s, const py::handle& key) {
                int c = channel_index(*s.f, key);
                return readonly_view(s.f, s.f->channel(c).data(), {s.f->height(), s.f->width()});
            }, py::arg("key"))
        .def("__getitem__", [](const PyField2D& s, const py::handle& key) {
                int c = channel_index(*s.f, key);
                return readonly_view(s.f, s.f->channel(c).data(), {s.f->height(), s.f->width()});
            })
        .def("__len__", [](const PyField2D& s) { return s.f->channels(); })
        .def("to_numpy", [](const PyField2D& s) {
                py::array_t<float> a({py::ssize_t(s.f->channels()), py::ssize_t(s.f->height()), py::ssize_t(s.f->width())});
                for (int c = 0; c < s.f->channels(); ++c)
                    std::memcpy(a.mutable_data(c), s.f->channel(c).data(), s.f->voxel_count() * sizeof(float));
                return a;
            }, "A writable copy of all channels, shape (channels, ny, nx).")
        .def("write", [](const PyField2D& s, const py::object& path, const py::object& format) { write_field(Value(s.f), path, format); },
             py::arg("path"), py::arg("format") = py::none(),
             "Writes the field to one file as a graph output would (format from the extension: exr, png, dds, ...; or given), atomically.")
        .def("__eq__", [](const PyField2D& a, const PyField2D& b) { return a.f == b.f || *a.f == *b.f; })
        .def("__repr__", [](const PyField2D& s) {
            return "<atlas.Field2D " + std::to_string(s.f->width()) + "x" + std::to_string(s.f->height()) + ", " +
                   std::to_string(s.f->channels()) + " channel(s)>";
        });
}

} // namespace atlas::python
