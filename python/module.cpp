// The Python module's native half, misalloc._misalloc: a scene built once and rendered
// many times, its arrays handed over without a copy where the layout allows. Options
// arrive as the command line's words and are parsed by the command line's own code
// (cli/RenderArgs.h, cli/CommandLine.h), so that Python and the CLI share every option,
// default and message; misalloc/__init__.py turns keyword arguments into those words.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <CL/opencl.hpp>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "Error.h"
#include "Interruption.h"
#include "cli/CommandLine.h"
#include "cli/RenderArgs.h"
#include "cli/Subcommand.h"
#include "report/ImageMetrics.h"
#include "scene/ExrIO.h"

namespace py = pybind11;
using namespace misalloc;

namespace {

// A render stopped by Ctrl-C, raised as KeyboardInterrupt once the GIL is held again.
struct PythonInterrupt {};

// While a render runs without the GIL: SIGINT and SIGTERM are blocked in its thread and
// in the threads it starts (PoCL's), and polled between kernel launches. A Python
// handler, or LLVM's while PoCL compiles a kernel in-process, would otherwise run on
// them: LLVM's deletes the temporary files of the compilation in flight.
thread_local InterruptionGuard* renderGuard = nullptr;

using FloatArray = py::array_t<float, py::array::c_style>;

void parseWords(CLI::App& app, std::vector<std::string> words) {
  std::reverse(words.begin(), words.end());  // CLI11 takes them last first
  app.parse(words);
  refuseEmptyValues(app);
}

// A std::vector handed to numpy, which then owns it: no copy.
template <class T>
py::array_t<T> ownedArray(std::vector<T>&& values, const std::vector<py::ssize_t>& shape) {
  auto* owned = new std::vector<T>(std::move(values));
  py::capsule free(owned, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return py::array_t<T>(shape, owned->data(), free);
}

RgbImage imageOf(const FloatArray& array) {
  RgbImage image{int(array.shape(1)), int(array.shape(0)), {}, {}};  // width, height
  image.rgb.assign(array.data(), array.data() + array.size());
  return image;
}

// Runs `work` without the GIL, so that other Python threads run meanwhile, and raises
// KeyboardInterrupt after Ctrl-C: at the next kernel launch (checkInterruption), or at
// the end if it came after the last one.
template <class Work>
auto withoutGil(Work&& work) {
  InterruptionGuard guard;
  InterruptionGuard* const outer = std::exchange(renderGuard, &guard);
  try {
    auto result = [&] {
      py::gil_scoped_release release;
      return work();
    }();
    renderGuard = outer;
    if (guard.requested()) throw PythonInterrupt{};
    return result;
  } catch (const PythonInterrupt&) {
    renderGuard = outer;
    if (!PyErr_Occurred()) PyErr_SetNone(PyExc_KeyboardInterrupt);
    throw py::error_already_set();
  } catch (...) {
    renderGuard = outer;
    throw;
  }
}

// A render's options, parsed by the command line's code: `args` keeps pointers into
// `app` (SceneArgs asks it which options were given), so the two live and die together.
struct ParsedArgs {
  CLI::App app;
  RenderArgs args;
};

// The scene, built once per envmap pdf that a render asks for, and its plain-pdf twin
// that finds references and costs.
struct BuiltScene {
  Scene scene, plain;
};

class PyScene {
 public:
  PyScene(std::vector<std::string> words, std::optional<FloatArray> envmap, const std::string& envmapName,
          std::optional<std::map<std::string, FloatArray>> gbuffer,
          const std::map<std::string, FloatArray>& gbufferMatrices, const std::string& gbufferName)
      : words_(std::move(words)) {
    if (envmap) {
      envmapTexels_ = std::make_shared<RgbImage>(imageOf(*envmap));
      envmapName_ = envmapName;
    }
    if (gbuffer) gbuffer_ = channelImage(*gbuffer, gbufferMatrices, gbufferName);
    built(parse({})->args);  // checks every input and builds the default pdf's tables now
  }

  py::dict render(const std::vector<std::string>& words, std::optional<FloatArray> referenceArray) {
    const Busy busy(busy_);
    const std::unique_ptr<ParsedArgs> parsed = parse(words);
    RenderArgs& args = parsed->args;
    const BuiltScene& s = built(args);
    RenderPlan plan = args.plan(s.scene);
    std::optional<Reference> given;
    if (referenceArray) {
      given = Reference{imageOf(*referenceArray), {}, "array", ""};
      checkSameSize(RgbImage{s.scene.grid.width, s.scene.grid.height, {}, {}}, given->image);
    } else {
      given = args.referenceFile(s.scene);
    }
    RenderOutcome outcome = withoutGil([&] { return args.render(s.scene, s.plain, plan, std::move(given)); });
    const nlohmann::json report = args.report(s.scene, plan, outcome);
    const py::ssize_t w = s.scene.grid.width, h = s.scene.grid.height, M = s.scene.techniqueCount();
    Rendering& r = outcome.rendering;
    py::dict out;
    out["image"] = ownedArray(std::move(r.image.rgb), {h, w, 3});
    out["alpha"] = ownedArray(std::move(r.alpha), {h, w, M});
    out["coverage"] = r.image.alpha.empty() ? py::object(py::none()) : ownedArray(std::move(r.image.alpha), {h, w});
    out["report"] = report.dump();
    return out;
  }

  py::dict reference(const std::vector<std::string>& words) {
    const Busy busy(busy_);
    const std::unique_ptr<ParsedArgs> parsed = parse(words);
    RenderArgs& args = parsed->args;
    const BuiltScene& s = built(args);
    Reference r = withoutGil([&] {
      return findReference(s.plain, args.referenceSpp, args.cacheDir, [&](const Scene& scene) {
        return args.devices.makeSampler(scene, SamplerConfig{}, args.localSize);
      });
    });
    const py::ssize_t w = r.image.width, h = r.image.height;
    py::dict out;
    out["image"] = ownedArray(std::move(r.image.rgb), {h, w, 3});
    out["standard_error"] =
        r.standardError.empty() ? py::object(py::none()) : ownedArray(std::move(r.standardError), {h, w, 3});
    out["source"] = r.source;
    out["path"] = r.path;
    return out;
  }

 private:
  // One render at a time: the GIL is released while it runs, and a second thread's render
  // of the same scene would share its tables and devices as they change. Set and cleared
  // with the GIL held.
  class Busy {
   public:
    explicit Busy(bool& busy) : busy_(busy) {
      if (busy_)
        throw std::runtime_error("this misalloc.Scene is rendering in another thread: use one Scene per thread");
      busy_ = true;
    }
    ~Busy() { busy_ = false; }

   private:
    bool& busy_;
  };

  std::unique_ptr<ParsedArgs> parse(const std::vector<std::string>& words) {
    auto parsed = std::make_unique<ParsedArgs>();
    RenderArgs& args = parsed->args;
    setParsingRules(parsed->app);
    args.add(parsed->app);
    std::vector<std::string> all = words_;
    all.insert(all.end(), words.begin(), words.end());
    parseWords(parsed->app, all);
    if (envmapTexels_) {
      args.scene.options.envmap = envmapName_;
      args.scene.options.envmapTexels = envmapTexels_;
    }
    if (gbuffer_) {
      args.scene.options.gbuffer.path = gbufferName_;
      args.scene.options.gbuffer.channels = gbuffer_;
    }
    args.resolveMethod();
    std::shared_ptr<SamplerDevices>& opened = devices_[args.devices.spec()];
    if (opened)
      args.devices.reuse(opened);
    else
      opened = args.devices.devices();
    return parsed;
  }

  const BuiltScene& built(RenderArgs& args) {
    const std::string pdf = envmapPdfName(args.scene.parsed().envmapPdf);
    auto found = scenes_.find(pdf);
    if (found != scenes_.end()) return found->second;
    args.scene.options.bankCacheDir = args.cacheDir;
    BuiltScene s = withoutGil([&] {
      Scene scene = args.scene.make();
      Scene plain = withPlainEnvmapPdf(scene);
      cacheOptimalBank(scene);
      return BuiltScene{std::move(scene), std::move(plain)};
    });
    return scenes_.emplace(pdf, std::move(s)).first->second;
  }

  std::shared_ptr<const ChannelImage> channelImage(const std::map<std::string, FloatArray>& planes,
                                                   const std::map<std::string, FloatArray>& matrices,
                                                   const std::string& name) {
    gbufferName_ = name;
    auto image = std::make_shared<ChannelImage>();
    for (const auto& [channel, plane] : planes) {
      image->header.channels.push_back(channel);
      image->header.height = int(plane.shape(0));
      image->header.width = int(plane.shape(1));
      image->planes[channel].assign(plane.data(), plane.data() + plane.size());
    }
    for (const auto& [matrix, values] : matrices)
      std::copy(values.data(), values.data() + 16, image->header.matrices[matrix].begin());
    return image;
  }

  std::vector<std::string> words_;  // the scene's options
  std::shared_ptr<const RgbImage> envmapTexels_;
  std::string envmapName_, gbufferName_;
  std::shared_ptr<const ChannelImage> gbuffer_;
  std::map<std::string, BuiltScene> scenes_;                        // by envmap pdf
  std::map<std::string, std::shared_ptr<SamplerDevices>> devices_;  // by --device
  bool busy_ = false;
};

// The options of `misalloc render` (RenderArgs) or of another subcommand, for the
// keyword arguments, docstrings and type stubs of misalloc/__init__.py.
py::list options(const std::string& command) {
  CLI::App app;
  setParsingRules(app);
  RenderArgs render;
  const CLI::App* source = &app;
  if (command == "render") {
    render.add(app);
  } else if (command == "compare") {
    source = addCompareCommand(app).command;
  } else {
    throw InputError("options: 'render' or 'compare'");
  }
  py::list out;
  for (const CLI::Option* o : source->get_options()) {
    if (o->get_name() == "--help") continue;
    py::dict d;
    d["name"] = o->get_name();
    d["group"] = o->get_group();
    d["default"] = o->get_default_str();
    d["help"] = o->get_description();
    d["flag"] = o->get_expected_max() == 0;
    out.append(d);
  }
  return out;
}

// Every channel of an EXR file by name, with the reader misalloc's inputs go through.
py::dict readExrFile(const std::string& path) {
  const ExrHeader header = readExrHeader(path);
  std::vector<std::vector<float>> planes = readExrChannels(path, header.channels);
  py::dict out;
  for (size_t c = 0; c < planes.size(); ++c)
    out[py::str(header.channels[c])] = ownedArray(std::move(planes[c]), {header.height, header.width});
  return out;
}

// `misalloc compare`, with the CLI's own code; returns its exit code (130: interrupted).
int compare(const std::vector<std::string>& words) {
  CLI::App app;
  setParsingRules(app);
  Subcommand command = addCompareCommand(app);
  std::vector<std::string> all{"compare"};
  all.insert(all.end(), words.begin(), words.end());
  std::reverse(all.begin(), all.end());
  app.parse(all);
  refuseEmptyValues(*command.command);
  py::gil_scoped_release release;
  return command.run();
}

}  // namespace

PYBIND11_MODULE(_misalloc, m) {
  m.doc() = "misalloc's native half; use the package misalloc";
  static py::exception<DeviceError> deviceError(m, "DeviceError", PyExc_RuntimeError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InputError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const std::filesystem::filesystem_error& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const CLI::ParseError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const DeviceError& e) {
      PyErr_SetString(deviceError.ptr(), e.what());
    } catch (const cl::Error& e) {
      PyErr_SetString(deviceError.ptr(), (std::string(e.what()) + " (code " + std::to_string(e.err()) + ")").c_str());
    }
  });
  // Ctrl-C while a render runs without the GIL, seen between kernel launches: a signal
  // pending in its thread (renderGuard), or one that another Python thread took.
  setInterruptionCheck([] {
    if (renderGuard && renderGuard->requested()) throw PythonInterrupt{};
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) throw PythonInterrupt{};
  });
  py::class_<PyScene>(m, "Scene")
      .def(py::init<std::vector<std::string>, std::optional<FloatArray>, std::string,
                    std::optional<std::map<std::string, FloatArray>>, std::map<std::string, FloatArray>, std::string>(),
           py::arg("words"), py::arg("envmap"), py::arg("envmap_name"), py::arg("gbuffer"), py::arg("gbuffer_matrices"),
           py::arg("gbuffer_name"))
      .def("render", &PyScene::render, py::arg("words"), py::arg("reference"))
      .def("reference", &PyScene::reference, py::arg("words"));
  m.def("options", &options, py::arg("command"));
  m.def("compare", &compare, py::arg("words"));
  m.def("read_exr", &readExrFile, py::arg("path"));
}
