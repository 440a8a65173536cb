// strata._strata: the Python bindings (pybind11) of the strata library. The Python package
// (python/strata/__init__.py) re-exports them with keyword-only parameters and documentation;
// the types and defaults are in python/strata/_strata.pyi.
//
// Every call that computes releases the GIL; the library's exceptions become strata.InvalidInput
// (ValueError), strata.IoError (OSError) and strata.Cancelled (RuntimeError), with the message
// the CLI prints after "strata: error: ".
#include "cli_util.h"
#include "reference.h"
#include "simplify_batch.h"

#include "strata/core/error.h"
#include "strata/core/format.h"
#include "strata/field/field.h"
#include "strata/geometry/checks.h"
#include "strata/geometry/scene.h"
#include "strata/io/mesh_slice.h"
#include "strata/io/scene_io.h"
#include "strata/simplify/simplify.h"
#include "strata/untangle/untangle.h"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace py = pybind11;
using namespace strata;

namespace {

using Array2 = py::array_t<double, py::array::c_style | py::array::forcecast>;

// (n, 2) float64 array of `points`, a copy.
py::array_t<double> to_array(const std::vector<Vec2>& points) {
    py::array_t<double> out({static_cast<py::ssize_t>(points.size()), py::ssize_t(2)});
    auto a = out.mutable_unchecked<2>();
    for (std::size_t i = 0; i < points.size(); ++i) {
        a(static_cast<py::ssize_t>(i), 0) = points[i].x;
        a(static_cast<py::ssize_t>(i), 1) = points[i].y;
    }
    return out;
}

// Points of an (n, 2) array (anything numpy converts to float64).
std::vector<Vec2> to_points(const py::handle& obj, const std::string& what) {
    const Array2 a = Array2::ensure(obj);
    if (!a) throw InvalidInput(what + ": points must be an (n, 2) array of numbers");
    if (a.ndim() != 2 || a.shape(1) != 2)
        throw InvalidInput(
            what + ": points must be an (n, 2) array (got shape " +
            py::str(py::tuple(py::cast(std::vector<py::ssize_t>(a.shape(), a.shape() + a.ndim()))))
                .cast<std::string>() +
            ")");
    const auto r = a.unchecked<2>();
    std::vector<Vec2> points(static_cast<std::size_t>(a.shape(0)));
    for (py::ssize_t i = 0; i < a.shape(0); ++i)
        points[static_cast<std::size_t>(i)] = Vec2(r(i, 0), r(i, 1));
    return points;
}

FieldBackend parse_backend(const std::string& name) {
    if (name == "grid") return FieldBackend::Grid;
    if (name == "exact") return FieldBackend::ExactBrute;
    if (name == "indexed") return FieldBackend::ExactIndexed;
    throw InvalidInput("backend: '" + name + "' not in {grid, exact, indexed}");
}

cli::InputCrossings parse_input_crossings(const std::string& name) {
    if (name == "untangle") return cli::InputCrossings::Untangle;
    if (name == "skip") return cli::InputCrossings::Skip;
    if (name == "fail") return cli::InputCrossings::Fail;
    throw InvalidInput("input_crossings: '" + name + "' not in {untangle, skip, fail}");
}

// Python's json.loads of `j` (stray bytes of a name that is not UTF-8 as U+FFFD, as the CLI's
// JSON reports have them).
py::object to_python(const nlohmann::json& j) {
    return py::module_::import("json").attr("loads")(
        j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
}

// A count option: a whole number >= `min` (as the CLI's add_count_option()).
std::size_t whole(const py::handle& v, const char* name, std::size_t min) {
    const auto x = v.cast<long long>();
    if (x < static_cast<long long>(min))
        throw InvalidInput(std::string("simplify: ") + name + " must be a whole number >= " +
                           std::to_string(min) + " (got " + std::to_string(x) + ")");
    return static_cast<std::size_t>(x);
}

// The untangling keyword arguments strata.simplify() and strata.untangle() share: true when
// `key` is one of them (and `u` is set).
bool untangle_option(UntangleParams& u, const std::string& key, const py::handle& v) {
    if (key == "backend")
        u.field.backend = parse_backend(v.cast<std::string>());
    else if (key == "alpha")
        u.alpha = v.cast<double>();
    else if (key == "beta")
        u.beta = v.cast<double>();
    else if (key == "gradient_steps")
        u.gradient_steps = v.cast<int>();
    else if (key == "tolerance")
        u.tolerance = v.cast<double>();
    else if (key == "max_rounds")
        u.max_rounds = v.cast<int>();
    else
        return false;
    return true;
}

// The simplify options from the keyword arguments (names as in strata.simplify()).
cli::SimplifyOptions simplify_options(const py::dict& kw) {
    cli::SimplifyOptions o;
    SimplifyParams& p = o.params;
    UntangleParams& u = p.untangling;
    for (const auto& item : kw) {
        const std::string key = py::str(item.first);
        const py::handle v = item.second;
        if (v.is_none()) continue;
        if (key == "remove")
            p.remove = v.cast<double>();
        else if (key == "keep")
            p.keep = whole(v, "keep", 0);
        else if (key == "max_error")
            p.max_error = v.cast<double>();
        else if (key == "decimator")
            p.decimator = v.cast<std::string>();
        else if (key == "seed")
            p.seed = v.cast<std::uint64_t>();
        else if (key == "untangle_batch")
            p.batch = whole(v, "untangle_batch", 1);
        else if (key == "n_out")
            p.n_out = whole(v, "n_out", 0);
        else if (key == "schedule") {
            const std::string s = v.cast<std::string>();
            if (s == "deferred")
                p.schedule = UntangleSchedule::Deferred;
            else if (s == "immediate")
                p.schedule = UntangleSchedule::Immediate;
            else
                throw InvalidInput("schedule: '" + s + "' not in {deferred, immediate}");
        } else if (untangle_option(u, key, v))
            continue;
        else if (key == "thickness")
            o.thickness = v.cast<double>();
        else if (key == "keep_gaps")
            p.keep_input_gaps = v.cast<double>();
        else if (key == "trim_ends")
            p.trim_ends = v.cast<bool>();
        else if (key == "global_untangle")
            p.global = v.cast<bool>();
        else if (key == "untangle")
            o.naive = !v.cast<bool>();
        else if (key == "compare_naive")
            o.compare_naive = v.cast<bool>();
        else if (key == "shape_matching")
            o.no_shape_matching = !v.cast<bool>();
        else if (key == "finish")
            o.no_finish = !v.cast<bool>();
        else if (key == "input_crossings")
            o.input_crossings = parse_input_crossings(v.cast<std::string>());
        else if (key == "time_limit") {
            o.time_limit = v.cast<double>();
            if (!std::isfinite(o.time_limit) || o.time_limit < 0.0)
                throw InvalidInput("time_limit must be a number of seconds >= 0 (got " +
                                   format_number(o.time_limit) + ")");
        } else
            throw py::type_error("simplify: unexpected keyword argument '" + key + "'");
    }
    // As the CLI does after parsing.
    if (o.no_shape_matching) u.shape = ShapeMode::None;
    if (o.no_finish) u.finish_separations = false;
    validate(p);
    return o;
}

py::dict outcome_dict(const cli::Outcome& o) {
    py::dict d;
    d["input"] = o.input;
    d["output"] = o.output;
    d["row"] = cli::batch_row(o);
    d["error"] = o.error.empty() ? py::object(py::none()) : py::object(py::str(o.error));
    d["skipped"] = o.skipped;
    d["untangled"] = static_cast<bool>(o.untangled);
    d["collision_free"] = o.report ? o.report->collision_free : false;
    d["entry"] = to_python(cli::batch_entry(o));
    d["peak_memory_mib"] = cli::peak_memory_mib();
    return d;
}

// A ProgressFn calling the Python callable `fn(stage, fraction)` (with the GIL) when it is not
// None: a false return cancels (strata.Cancelled); an exception it raises (or a pending
// KeyboardInterrupt) cancels too and is raised again by rethrow_if_any() once the work stopped.
struct PythonProgress {
    py::object fn;
    std::shared_ptr<py::error_already_set> error;

    ProgressFn callback() {
        if (fn.is_none()) return {};
        return [this](std::string_view stage, double fraction) {
            py::gil_scoped_acquire acquire;
            if (error) return false;
            try {
                if (PyErr_CheckSignals() != 0) throw py::error_already_set();
                return py::cast<bool>(fn(std::string(stage), fraction));
            } catch (py::error_already_set& e) {
                error = std::make_shared<py::error_already_set>(std::move(e));
                return false;
            }
        };
    }
    void rethrow_if_any() {
        if (error) throw *error;
    }
};

// A grid of a layer's field, row j from the top (y = ymax - (j + 0.5) h), column i from the left.
struct FieldGrid {
    std::vector<double> value, gx, gy, border;
    std::vector<std::uint8_t> in_band;
    std::size_t rows = 0, cols = 0;
    Box2 box;
    ResolvedFieldParams params;
};

}  // namespace

PYBIND11_MODULE(_strata, m) {
    m.doc() =
        "strata's C++ library (collision-free simplification of 2D multi-layered shapes); "
        "use the package strata, not this module.";

    static py::exception<InvalidInput> invalid(m, "InvalidInput", PyExc_ValueError);
    static py::exception<IoError> io_error(m, "IoError", PyExc_OSError);
    static py::exception<Cancelled> cancelled(m, "Cancelled", PyExc_RuntimeError);
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const InvalidInput& e) {
            PyErr_SetString(invalid.ptr(), e.what());
        } catch (const IoError& e) {
            PyErr_SetString(io_error.ptr(), e.what());
        } catch (const Cancelled& e) {
            PyErr_SetString(cancelled.ptr(), e.what());
        }
    });

    py::class_<Layer>(m, "Layer")
        .def(py::init([](const py::handle& points, std::string name, bool closed, double thickness,
                         double weight, std::optional<double> alpha, std::optional<double> beta,
                         std::optional<std::vector<std::string>> outer) {
                 Layer l;
                 l.points = to_points(points, name.empty() ? "layer" : "layer '" + name + "'");
                 l.name = std::move(name);
                 l.closed = closed;
                 l.thickness = thickness;
                 l.weight = weight;
                 l.alpha = alpha;
                 l.beta = beta;
                 l.outer = std::move(outer);
                 return l;
             }),
             py::arg("points"), py::kw_only(), py::arg("name") = "", py::arg("closed") = false,
             py::arg("thickness") = 0.0, py::arg("weight") = 1.0, py::arg("alpha") = py::none(),
             py::arg("beta") = py::none(), py::arg("outer") = py::none())
        .def_readonly("name", &Layer::name)
        .def_property_readonly("points", [](const Layer& l) { return to_array(l.points); })
        .def_readonly("closed", &Layer::closed)
        .def_readonly("thickness", &Layer::thickness)
        .def_readonly("weight", &Layer::weight)
        .def_readonly("alpha", &Layer::alpha)
        .def_readonly("beta", &Layer::beta)
        .def_readonly("outer", &Layer::outer)
        .def("__len__", [](const Layer& l) { return l.points.size(); })
        .def_property_readonly("length", &Layer::length)
        .def("__repr__", [](const Layer& l) {
            return "<strata.Layer '" + l.name + "': " + std::to_string(l.points.size()) +
                   " points, " + (l.closed ? "closed" : "open") + ">";
        });

    py::class_<Scene>(m, "Scene")
        .def(py::init([](std::vector<Layer> layers, std::string units) {
                 py::gil_scoped_release release;
                 return Scene(std::move(layers), std::move(units));
             }),
             py::arg("layers"), py::kw_only(), py::arg("units") = "")
        .def("__len__", &Scene::size)
        .def("__getitem__",
             [](const Scene& s, py::object key) -> Layer {
                 if (py::isinstance<py::str>(key)) {
                     const std::string name = key.cast<std::string>();
                     const auto i = s.find(name);
                     if (!i) throw py::key_error("no layer named '" + name + "'");
                     return s.layer(*i);
                 }
                 auto i = key.cast<py::ssize_t>();
                 const auto n = static_cast<py::ssize_t>(s.size());
                 if (i < 0) i += n;
                 if (i < 0 || i >= n) throw py::index_error("layer index out of range");
                 return s.layer(static_cast<std::size_t>(i));
             })
        .def_property_readonly("layers", &Scene::layers)
        .def_property_readonly("names",
                               [](const Scene& s) {
                                   std::vector<std::string> names;
                                   for (const Layer& l : s.layers()) names.push_back(l.name);
                                   return names;
                               })
        .def_property_readonly("units", &Scene::units)
        .def_property_readonly("notes", [](const Scene& s) { return s.diagnostics().notes; })
        .def_property_readonly("removed_duplicates",
                               [](const Scene& s) { return s.diagnostics().removed_duplicates; })
        .def_property_readonly("vertex_count", &Scene::vertex_count)
        .def_property_readonly("is_implicit_stack", &Scene::is_implicit_stack)
        .def_property_readonly("bounds",
                               [](const Scene& s) {
                                   const Box2 b = s.bounds();
                                   return py::make_tuple(b.min.x, b.min.y, b.max.x, b.max.y);
                               })
        .def("required_separation", &Scene::required_separation, py::arg("a"), py::arg("b"))
        .def(
            "relation",
            [](const Scene& s, std::size_t a, std::size_t b) {
                return relation_name(s.relation(a, b));
            },
            py::arg("a"), py::arg("b"))
        .def(
            "with_points",
            [](const Scene& s, std::size_t i, const py::handle& points) {
                Scene out = s;
                if (i >= s.size()) throw py::index_error("layer index out of range");
                out.set_points(i, to_points(points, "layer '" + s.layer(i).name + "'"));
                return out;
            },
            py::arg("layer"), py::arg("points"))
        .def("__repr__", [](const Scene& s) {
            return "<strata.Scene: " + std::to_string(s.size()) + " layers, " +
                   std::to_string(s.vertex_count()) + " vertices>";
        });

    m.def(
        "read_scene",
        [](const std::filesystem::path& path) {
            py::gil_scoped_release release;
            return read_scene(path);
        },
        py::arg("path"));
    m.def(
        "write_scene",
        [](const Scene& scene, const std::filesystem::path& path) {
            py::gil_scoped_release release;
            write_scene(scene, path);
        },
        py::arg("scene"), py::arg("path"));

    py::class_<LayerSimplifyReport>(m, "LayerReport")
        .def_readonly("name", &LayerSimplifyReport::name)
        .def_readonly("before", &LayerSimplifyReport::before)
        .def_readonly("after", &LayerSimplifyReport::after)
        .def_readonly("target", &LayerSimplifyReport::target)
        .def_readonly("refused", &LayerSimplifyReport::refused)
        .def_readonly("untangled", &LayerSimplifyReport::untangled)
        .def_readonly("hausdorff", &LayerSimplifyReport::hausdorff)
        .def_readonly("max_displacement", &LayerSimplifyReport::max_displacement)
        .def("__repr__", [](const LayerSimplifyReport& l) {
            return "<strata.LayerReport '" + l.name + "': " + std::to_string(l.before) + " -> " +
                   std::to_string(l.after) + ">";
        });

    py::class_<SimplifyReport>(m, "SimplifyReport")
        .def_readonly("layers", &SimplifyReport::layers)
        .def_readonly("removed", &SimplifyReport::removed)
        .def_readonly("untangle_calls", &SimplifyReport::untangle_calls)
        .def_readonly("refused", &SimplifyReport::refused)
        .def_readonly("gave_up", &SimplifyReport::gave_up)
        .def_readonly("chord_shifts", &SimplifyReport::chord_shifts)
        .def_readonly("shape_refused", &SimplifyReport::shape_refused)
        .def_readonly("deferred", &SimplifyReport::deferred)
        .def_readonly("batches", &SimplifyReport::batches)
        .def_readonly("targets_met", &SimplifyReport::targets_met)
        .def_readonly("raised_separations", &SimplifyReport::raised_separations)
        .def_readonly("rolled_vertices", &SimplifyReport::rolled_vertices)
        .def_readonly("restored", &SimplifyReport::restored)
        .def_readonly("trimmed_ends", &SimplifyReport::trimmed_ends)
        .def_readonly("crossings", &SimplifyReport::crossings)
        .def_readonly("self_crossings", &SimplifyReport::self_crossings)
        .def_readonly("nesting_violations", &SimplifyReport::nesting_violations)
        .def_readonly("min_separation_ratio", &SimplifyReport::min_separation_ratio)
        .def_readonly("collision_free", &SimplifyReport::collision_free)
        .def_readonly("seconds_total", &SimplifyReport::seconds_total)
        .def_readonly("seconds_decimate", &SimplifyReport::seconds_decimate)
        .def_readonly("seconds_fields", &SimplifyReport::seconds_fields)
        .def_readonly("seconds_untangle", &SimplifyReport::seconds_untangle)
        .def_readonly("seconds_finish", &SimplifyReport::seconds_finish)
        .def_readonly("seconds_check", &SimplifyReport::seconds_check)
        .def_property_readonly("hausdorff", &cli::max_hausdorff)
        .def("to_dict",
             [](const SimplifyReport& r) { return to_python(cli::report_json(r, nullptr)); });

    // _simplify(scene, options) -> (scene, report, naive report or None, input untangling
    // as a dict or None); the options are strata.simplify()'s keyword arguments.
    m.def("_simplify", [](const Scene& scene, const py::dict& kw, const py::object& progress) {
        PythonProgress python_progress{progress, nullptr};
        const cli::SimplifyOptions opt = simplify_options(kw);
        if (opt.input_crossings == cli::InputCrossings::Skip)
            throw InvalidInput(
                "simplify: input_crossings 'skip' is for strata.batch (use "
                "'untangle' or 'fail')");
        if (opt.time_limit > 0.0)
            throw InvalidInput(
                "simplify: time_limit is for strata.batch (a progress callback that returns "
                "False stops strata.simplify())");
        cli::Outcome out;
        std::optional<cli::InputUntangling> untangled;
        Scene result;
        {
            py::gil_scoped_release release;
            const Scene input = cli::with_default_thickness(scene, opt.thickness);
            try {
                const ProgressFn callback = python_progress.callback();
                const std::optional<Scene> prepared = cli::prepare_input(
                    input, "simplify", opt.input_crossings, opt.params, untangled, callback);
                out = cli::run_one(*prepared, opt, callback, result, nullptr);
            } catch (const Cancelled&) {
                py::gil_scoped_acquire acquire;
                python_progress.rethrow_if_any();
                throw;
            }
        }
        return py::make_tuple(
            result, *out.report, out.naive ? py::cast(*out.naive) : py::object(py::none()),
            untangled ? to_python(cli::untangling_json(*untangled)) : py::object(py::none()));
    });

    py::class_<UntangleReport>(m, "UntangleReport")
        .def_readonly("tries", &UntangleReport::tries)
        .def_readonly("passes", &UntangleReport::passes)
        .def_readonly("rounds", &UntangleReport::rounds)
        .def_readonly("converged", &UntangleReport::converged)
        .def_readonly("collision_free", &UntangleReport::collision_free)
        .def_readonly("moved_vertices", &UntangleReport::moved_vertices)
        .def_readonly("max_displacement", &UntangleReport::max_displacement)
        .def_readonly("crossings_before", &UntangleReport::crossings_before)
        .def_readonly("crossings_after", &UntangleReport::crossings_after)
        .def_readonly("self_crossings_after", &UntangleReport::self_crossings_after)
        .def_readonly("nesting_violations_after", &UntangleReport::nesting_violations_after)
        .def_readonly("min_separation_ratio_after", &UntangleReport::min_separation_ratio_after)
        .def_readonly("inferred_sides", &UntangleReport::inferred_sides)
        .def_readonly("gave_up", &UntangleReport::gave_up)
        .def_readonly("input_kept", &UntangleReport::input_kept)
        .def_property_readonly(
            "seconds",
            [](const UntangleReport& r) {
                return r.seconds_fields + r.seconds_untangle + r.seconds_finish + r.seconds_check;
            },
            "Seconds of the tries, summed: tries after a failed one can run two at a time, so it "
            "can exceed the call's time");

    m.def("_untangle", [](const Scene& scene, const py::dict& kw, const py::object& progress) {
        PythonProgress python_progress{progress, nullptr};
        UntangleParams u;
        bool global_order = false;
        for (const auto& item : kw) {
            const std::string key = py::str(item.first);
            const py::handle v = item.second;
            if (v.is_none()) continue;
            if (untangle_option(u, key, v))
                continue;
            else if (key == "global_order")
                global_order = v.cast<bool>();
            else if (key == "max_passes")
                u.max_passes = v.cast<int>();
            else if (key == "shape_matching") {
                if (!v.cast<bool>()) u.shape = ShapeMode::None;
            } else if (key == "finish")
                u.finish_separations = v.cast<bool>();
            else if (key == "give_up_when_stalled")
                u.give_up_when_stalled = v.cast<bool>();
            else
                throw py::type_error("untangle: unexpected keyword argument '" + key + "'");
        }
        validate(u);
        Scene out = scene;
        UntangleReport r;
        {
            py::gil_scoped_release release;
            try {
                r = global_order ? untangle(out, u, python_progress.callback())
                                 : untangle_inferring_sides(out, u, python_progress.callback());
            } catch (const Cancelled&) {
                py::gil_scoped_acquire acquire;
                python_progress.rethrow_if_any();
                throw;
            }
        }
        return py::make_tuple(out, r);
    });

    m.def(
        "_check",
        [](const Scene& scene, const std::optional<Scene>& reference, double near_distance,
           double separation_tolerance, double hausdorff_tolerance) {
            CheckParams params;
            params.near_distance = near_distance;
            params.separation_tolerance = separation_tolerance;
            validate(params);
            CheckReport r;
            std::map<std::string, double> h;
            {
                py::gil_scoped_release release;
                std::optional<cli::Reference> ref;
                if (reference) {
                    // As `strata check --reference`: open layers take their outside side and
                    // the sides of their vertices (a rolled part) from the reference.
                    ref = cli::match_reference(*reference, scene, params.near_distance, false,
                                               "reference");
                    params.outside_sides = ref->outside_sides;
                    params.input_sides = &ref->sides;
                    const Box2 b = reference->bounds();
                    const double diagonal = std::hypot(b.max.x - b.min.x, b.max.y - b.min.y);
                    for (std::size_t i = 0; i < scene.size(); ++i)
                        if (const auto j = reference->find(scene.layer(i).name))
                            h[scene.layer(i).name] =
                                hausdorff(scene.layer(i), reference->layer(*j),
                                          hausdorff_tolerance * std::max(diagonal, 1e-300))
                                    .symmetric();
                }
                r = check_scene(scene, params);
            }
            py::dict d;
            d["collision_free"] = r.is_collision_free();
            d["crossings"] = r.crossing_count;
            d["touches"] = r.touch_count;
            d["self_crossings"] = r.self_crossing_count;
            d["nesting_violations"] = r.nesting_violation_count;
            d["separation_violations"] = r.separation_violation_count;
            d["min_separation_ratio"] = r.min_separation_ratio;
            d["near_distance"] = r.near_distance;
            py::list where;
            for (const Crossing& c : r.crossings)
                where.append(py::make_tuple(scene.layer(c.layer_a).name, c.segment_a,
                                            scene.layer(c.layer_b).name, c.segment_b,
                                            py::make_tuple(c.point.x, c.point.y), c.is_touch));
            d["crossing_list"] = where;
            py::list pairs;
            for (const PairSeparation& p : r.pairs)
                pairs.append(py::make_tuple(scene.layer(p.layer_a).name,
                                            scene.layer(p.layer_b).name, p.gap, p.required));
            d["pairs"] = pairs;
            d["hausdorff"] = h;
            d["summary"] = r.is_collision_free() ? std::string() : cli::tangle_summary(scene, r);
            return d;
        },
        py::arg("scene"), py::arg("reference"), py::arg("near_distance"),
        py::arg("separation_tolerance"), py::arg("hausdorff_tolerance"));

    m.def("_slice", [](const py::list& meshes, const std::string& axis,
                       const std::vector<double>& heights, bool split_components,
                       const std::vector<std::string>& order, double thickness,
                       const std::map<std::string, double>& mesh_thickness,
                       const std::string& units, bool weld, double weld_tolerance) {
        SliceParams p;
        p.axis = parse_axis(axis);
        p.heights = heights;
        p.split_components = split_components;
        p.order = order;
        p.thickness = thickness;
        p.mesh_thickness = mesh_thickness;
        p.units = units;
        p.weld.enabled = weld;
        p.weld.tolerance = weld_tolerance;
        validate(p);
        // Each mesh: a path, (name, path), or (name, vertices (n, 3), faces (m, k)).
        std::vector<std::filesystem::path> paths;
        std::vector<SliceMesh> loaded;
        std::vector<std::string> names;  // of the meshes read from `paths`
        std::vector<int> is_path;
        for (const py::handle& item : meshes) {
            if (py::isinstance<py::tuple>(item)) {
                const auto t = item.cast<py::tuple>();
                if (t.size() == 2) {  // (name, path)
                    names.push_back(t[0].cast<std::string>());
                    paths.push_back(t[1].cast<std::filesystem::path>());
                    loaded.emplace_back();
                    is_path.push_back(static_cast<int>(loaded.size() - 1));
                    continue;
                }
                if (t.size() != 3)
                    throw InvalidInput(
                        "slice: a mesh is a path, (name, path) or (name, vertices, faces)");
                const std::string name = t[0].cast<std::string>();
                const auto v =
                    py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(t[1]);
                const auto f =
                    py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(
                        t[2]);
                if (!v || v.ndim() != 2 || v.shape(1) != 3)
                    throw InvalidInput("slice: mesh '" + name +
                                       "': vertices must be an (n, 3) array");
                if (!f || f.ndim() != 2 || f.shape(1) < 3)
                    throw InvalidInput("slice: mesh '" + name +
                                       "': faces must be an (m, k >= 3) array of indices");
                std::vector<glm::dvec3> vertices(static_cast<std::size_t>(v.shape(0)));
                const auto rv = v.unchecked<2>();
                for (py::ssize_t i = 0; i < v.shape(0); ++i)
                    vertices[static_cast<std::size_t>(i)] =
                        glm::dvec3(rv(i, 0), rv(i, 1), rv(i, 2));
                std::vector<std::vector<std::uint32_t>> faces(static_cast<std::size_t>(f.shape(0)));
                const auto rf = f.unchecked<2>();
                for (py::ssize_t i = 0; i < f.shape(0); ++i)
                    for (py::ssize_t k = 0; k < f.shape(1); ++k) {
                        const std::int64_t index = rf(i, k);
                        if (index < 0 || index >= v.shape(0))
                            throw InvalidInput("slice: mesh '" + name + "': face " +
                                               std::to_string(i) + " has vertex index " +
                                               std::to_string(index) + " out of [0, " +
                                               std::to_string(v.shape(0)) + ")");
                        faces[static_cast<std::size_t>(i)].push_back(
                            static_cast<std::uint32_t>(index));
                    }
                loaded.push_back(make_slice_mesh(name, std::move(vertices), faces));
            } else {
                paths.push_back(item.cast<std::filesystem::path>());
                names.emplace_back();  // the file stem
                loaded.emplace_back();
                is_path.push_back(static_cast<int>(loaded.size() - 1));
            }
        }
        SliceReport report;
        {
            py::gil_scoped_release release;
            for (std::size_t k = 0; k < paths.size(); ++k)
                loaded[static_cast<std::size_t>(is_path[k])] = read_slice_mesh(paths[k], names[k]);
            report = slice_meshes(loaded, p);
        }
        py::list out;
        for (const PlaneSlice& s : report.slices)
            out.append(s.scene ? py::cast(*s.scene) : py::none());
        return out;
    });

    m.def("_sample_field", [](const Scene& scene, std::size_t layer, double spacing,
                              std::optional<std::vector<double>> box, const std::string& backend,
                              double voxel_size, double band_width, double margin) {
        if (layer >= scene.size())
            throw InvalidInput("sample_field: no layer " + std::to_string(layer));
        if (!(spacing > 0.0) || !std::isfinite(spacing))
            throw InvalidInput("sample_field: spacing must be > 0 (got " + std::to_string(spacing) +
                               ")");
        FieldParams params;
        params.backend = parse_backend(backend);
        params.voxel_size = voxel_size;
        params.band_width = band_width;
        validate(params);
        FieldGrid g;
        {
            py::gil_scoped_release release;
            std::vector<int> sides(scene.size());
            for (std::size_t i = 0; i < scene.size(); ++i) sides[i] = outside_side(scene, i);
            const SceneFields fields(scene, params, sides);
            g.params = fields.params();
            if (box) {
                if (box->size() != 4 || !((*box)[2] > (*box)[0]) || !((*box)[3] > (*box)[1]))
                    throw InvalidInput(
                        "sample_field: bounds must be (xmin, ymin, xmax, ymax) with xmin < xmax, "
                        "ymin < ymax");
                g.box.min = Vec2((*box)[0], (*box)[1]);
                g.box.max = Vec2((*box)[2], (*box)[3]);
            } else {
                g.box = scene.layer(layer).bounds().inflated(
                    margin >= 0.0 ? margin : 2.0 * g.params.band_width);
            }
            const Vec2 size = g.box.max - g.box.min;
            const double cells = std::ceil(size.x / spacing) * std::ceil(size.y / spacing);
            if (cells > 1e8)
                throw InvalidInput("sample_field: " + std::to_string(cells) +
                                   " samples is too many (spacing " + std::to_string(spacing) +
                                   ")");
            g.cols =
                std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(size.x / spacing)));
            g.rows =
                std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(size.y / spacing)));
            const std::size_t n = g.rows * g.cols;
            g.value.resize(n);
            g.gx.resize(n);
            g.gy.resize(n);
            g.border.resize(n);
            g.in_band.resize(n);
            const LayerField& f = fields.field(layer);
            for (std::size_t j = 0; j < g.rows; ++j)
                for (std::size_t i = 0; i < g.cols; ++i) {
                    const FieldSample s =
                        f.sample(Vec2(g.box.min.x + (static_cast<double>(i) + 0.5) * spacing,
                                      g.box.max.y - (static_cast<double>(j) + 0.5) * spacing));
                    const std::size_t k = j * g.cols + i;
                    g.value[k] = s.value;
                    g.gx[k] = s.gradient.x;
                    g.gy[k] = s.gradient.y;
                    g.border[k] = s.border;
                    g.in_band[k] = s.in_band ? 1 : 0;
                }
        }
        const std::vector<py::ssize_t> shape{static_cast<py::ssize_t>(g.rows),
                                             static_cast<py::ssize_t>(g.cols)};
        auto array = [&](const std::vector<double>& v) {
            py::array_t<double> a(shape);
            std::copy(v.begin(), v.end(), a.mutable_data());
            return a;
        };
        py::array_t<bool> band(shape);
        std::transform(g.in_band.begin(), g.in_band.end(), band.mutable_data(),
                       [](std::uint8_t b) { return b != 0; });
        py::dict d;
        d["value"] = array(g.value);
        d["gradient_x"] = array(g.gx);
        d["gradient_y"] = array(g.gy);
        d["border"] = array(g.border);
        d["in_band"] = band;
        d["bounds"] = py::make_tuple(g.box.min.x, g.box.min.y, g.box.max.x, g.box.max.y);
        d["band_width"] = g.params.band_width;
        d["voxel_size"] = g.params.backend == FieldBackend::Grid ? g.params.voxel_size : 0.0;
        return d;
    });

    // Batch: what `strata simplify FOLDER -o OUT` does per slice, and its table.
    m.def("_expand_inputs", &cli::expand_inputs);
    m.def("_batch_output", &cli::batch_output);
    m.def("_batch_header", &cli::batch_header);
    m.def("_batch_slice",
          [](const std::string& input, const std::string& output, const py::dict& kw) {
              const cli::SimplifyOptions opt = simplify_options(kw);
              cli::Outcome o;
              {
                  py::gil_scoped_release release;
                  o = cli::simplify_slice(input, output, opt);
              }
              return outcome_dict(o);
          });
    m.def("_validate_options", [](const py::dict& kw) { simplify_options(kw); });
    m.def("_batch_footer", [](std::size_t slices, std::size_t failed, std::size_t skipped,
                              std::size_t untangled, std::size_t tangled, double peak) {
        cli::BatchTotals t;
        t.slices = slices;
        t.failed = failed;
        t.skipped = skipped;
        t.untangled = untangled;
        t.tangled = tangled;
        return cli::batch_footer(t, peak);
    });
    m.def("_peak_memory_mib", &cli::peak_memory_mib);
}
