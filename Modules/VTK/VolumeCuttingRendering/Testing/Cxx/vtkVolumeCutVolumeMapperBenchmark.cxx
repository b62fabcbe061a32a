// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// The mapper's two paths against each other and against VTK's stock GPU
// ray caster, in C++ so that it runs where the Python wheels do not (the GPU
// machine lent through the device tool has another Python).
//
// As a test (no arguments beyond the temporary directory): a small cut cube,
// the GLSL path forced, and its image compared with the CPU path's: the test
// fails when they disagree. With "full" after the directory: the same check
// at the benchmark's sizes, then frame times of both paths and of
// vtkGPUVolumeRayCastMapper on the CT masked by the cut (same data, view and
// process), and the frame after one burr stroke; one JSON object per line.
// The sizes are issue 12's GPU table: 256^3 and 512^3 at 512^2, 1024^2 and
// 1920 x 1080, the last also with ten segments (a label map across the
// cube); the GPU path's first image after an empty program cache is timed
// too (program build included). With "gpu" instead of "full": the same
// without the CPU path. A third argument sets the repeats (default 15), a
// fourth one volume size instead of the table's.
#include "vtkVolumeCutField.h"
#include "vtkVolumeCutOpenGLRayCaster.h"
#include "vtkVolumeCutRayCaster.h"
#include "vtkVolumeCutVolumeMapper.h"

#include <vtkAutoInit.h>
#include <vtkCamera.h>
#include <vtkColorTransferFunction.h>
#include <vtkContourValues.h>
#include <vtkFloatArray.h>
#include <vtkGPUVolumeRayCastMapper.h>
#include <vtkImageData.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkOpenGLRenderWindow.h>
#include <vtkPiecewiseFunction.h>
#include <vtkPointData.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkUnsignedCharArray.h>
#include <vtkVolume.h>
#include <vtkVolumeProperty.h>

VTK_MODULE_INIT(vtkRenderingOpenGL2);
VTK_MODULE_INIT(vtkRenderingVolumeOpenGL2);

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

namespace
{
constexpr double Bone = 1000.0;

/// The analytic cut cube of VolumeCuttingLib.data.analyticscene.default_scene:
/// faces through voxel centres, a two-voxel ramp, cuts across a corner, an
/// edge, along an edge and into a face, all scaled with the grid.
struct CutCube
{
  int Dimensions;
  double Spacing = 0.5;
  double Center;
  double Half;
  vtkNew<vtkImageData> Intensities;
  vtkNew<vtkImageData> Masked;
  vtkNew<vtkImageData> Labels;
  vtkNew<vtkMatrix4x4> IJKToRAS;
  vtkNew<vtkVolumeCutField> Cut;

  explicit CutCube(int dimensions)
    : Dimensions(dimensions)
  {
    const double scale = dimensions / 64.0;
    this->Center = (dimensions / 2) * this->Spacing;
    this->Half = std::round(14 * scale) * this->Spacing;
    for (int axis = 0; axis < 3; ++axis)
    {
      this->IJKToRAS->SetElement(axis, axis, this->Spacing);
    }
    this->MakeIntensities();
    this->Cut->SetMaximumStrokeLength(1.0e6);
    this->Cut->Initialize(this->Intensities->GetDimensions(), this->IJKToRAS, 2);
    const double c = this->Center;
    const double h = this->Half;
    const double s = this->Spacing * scale;
    const double corner[3] = { c + h - 0.37 * s, c + h - 0.61 * s, c + h + 0.23 * s };
    this->Cut->CutCapsule(corner, corner, 5.3 * s);
    const double edge[3] = { c + h + 0.81 * s, c + 0.17 * s, c + h - 1.93 * s };
    this->Cut->CutCapsule(edge, edge, 4.1 * s);
    this->CutLine(c - 4.31 * s, c + h + 0.42 * s, c + h - 0.27 * s, 1.0, 0.0, 0.0, 3.2 * s);
    this->CutLine(c + 5.13 * s, c - 3.71 * s, c + h, 0.2, 0.3, 1.0, 3.6 * s);
    this->MakeMasked();
    this->MakeLabels();
  }

  /// Segments 1..SegmentCount: slabs of the cube along z, its ramp included,
  /// each an iso-surface segment at the same iso-value.
  static constexpr int SegmentCount = 10;
  void MakeLabels()
  {
    const int n = this->Dimensions;
    this->Labels->SetDimensions(n, n, n);
    this->Labels->AllocateScalars(VTK_UNSIGNED_SHORT, 1);
    auto* labels = static_cast<unsigned short*>(this->Labels->GetScalarPointer());
    const double low = this->Center - this->Half - 2.0 * this->Spacing;
    const double high = this->Center + this->Half + 2.0 * this->Spacing;
    auto inside = [&](int i) { return i * this->Spacing >= low && i * this->Spacing <= high; };
    for (int k = 0; k < n; ++k)
    {
      const int segment = 1 + std::min(SegmentCount - 1, static_cast<int>(SegmentCount * (k * this->Spacing - low) / (high - low)));
      for (int j = 0; j < n; ++j)
      {
        for (int i = 0; i < n; ++i)
        {
          labels[(static_cast<size_t>(k) * n + j) * n + i] = static_cast<unsigned short>(inside(i) && inside(j) && inside(k) ? segment : 0);
        }
      }
    }
  }

  void CutLine(double x, double y, double z, double dx, double dy, double dz, double radius)
  {
    const double length = std::sqrt(dx * dx + dy * dy + dz * dz);
    const double reach = 2.0 * this->Dimensions * this->Spacing / length;
    const double p0[3] = { x - reach * dx, y - reach * dy, z - reach * dz };
    const double p1[3] = { x + reach * dx, y + reach * dy, z + reach * dz };
    this->Cut->CutCapsule(p0, p1, radius);
  }

  void MakeIntensities()
  {
    const int n = this->Dimensions;
    this->Intensities->SetDimensions(n, n, n);
    this->Intensities->AllocateScalars(VTK_FLOAT, 1);
    std::vector<float> q(n);
    for (int i = 0; i < n; ++i)
    {
      q[i] = static_cast<float>(std::abs(i * this->Spacing - this->Center) - this->Half);
    }
    const float width = static_cast<float>(2.0 * this->Spacing);
    float* values = static_cast<float*>(this->Intensities->GetScalarPointer());
    for (int k = 0; k < n; ++k)
    {
      for (int j = 0; j < n; ++j)
      {
        for (int i = 0; i < n; ++i)
        {
          const float x = std::max(q[i], 0.0f);
          const float y = std::max(q[j], 0.0f);
          const float z = std::max(q[k], 0.0f);
          const float distance = std::sqrt(x * x + y * y + z * z) + std::min(std::max({ q[i], q[j], q[k] }), 0.0f);
          values[(static_cast<size_t>(k) * n + j) * n + i] = static_cast<float>(Bone) * std::min(1.0f, std::max(0.0f, 0.5f - distance / width));
        }
      }
    }
  }

  /// Today's Slicer approach for the stock mapper: voxels removed by at least half set to air.
  void MakeMasked()
  {
    vtkNew<vtkImageData> fraction;
    this->Cut->ExportRemovedFraction(fraction);
    this->Masked->DeepCopy(this->Intensities);
    float* values = static_cast<float*>(this->Masked->GetScalarPointer());
    vtkDataArray* removed = fraction->GetPointData()->GetScalars();
    for (vtkIdType index = 0; index < removed->GetNumberOfTuples(); ++index)
    {
      if (removed->GetComponent(index, 0) >= 0.5)
      {
        values[index] = 0.0f;
      }
    }
  }
};

vtkSmartPointer<vtkVolume> OurVolume(CutCube& scene, int path, bool segments = false)
{
  vtkNew<vtkVolumeCutVolumeMapper> mapper;
  mapper->SetInputData(scene.Intensities);
  mapper->GetRayCaster()->SetIsoValue(0.5 * Bone);
  mapper->GetRayCaster()->AddCutField(scene.Cut);
  if (segments)
  {
    mapper->GetRayCaster()->SetLabelMap(scene.Labels);
    for (int segment = 1; segment <= CutCube::SegmentCount; ++segment)
    {
      const double color[3] = { 0.5 + 0.05 * segment, 0.9 - 0.04 * segment, 0.6 };
      mapper->GetRayCaster()->SetSegmentAppearance(segment, color, 1.0, 0.5 * Bone);
    }
  }
  mapper->SetRequestedRenderPath(path);
  auto volume = vtkSmartPointer<vtkVolume>::New();
  volume->SetMapper(mapper);
  volume->SetUserMatrix(scene.IJKToRAS);
  return volume;
}

vtkSmartPointer<vtkVolume> StockVolume(CutCube& scene)
{
  vtkNew<vtkGPUVolumeRayCastMapper> mapper;
  mapper->SetInputData(scene.Masked);
  mapper->SetBlendModeToIsoSurface();
  mapper->SetAutoAdjustSampleDistances(0);
  mapper->SetSampleDistance(0.5 * scene.Spacing);
  vtkNew<vtkVolumeProperty> property;
  property->ShadeOn();
  property->SetInterpolationTypeToLinear();
  property->GetIsoSurfaceValues()->SetValue(0, 0.5 * Bone);
  vtkNew<vtkColorTransferFunction> color;
  color->AddRGBPoint(0.0, 0.95, 0.92, 0.84);
  color->AddRGBPoint(Bone, 0.95, 0.92, 0.84);
  vtkNew<vtkPiecewiseFunction> opacity;
  opacity->AddPoint(0.0, 1.0);
  opacity->AddPoint(Bone, 1.0);
  property->SetColor(color);
  property->SetScalarOpacity(opacity);
  auto volume = vtkSmartPointer<vtkVolume>::New();
  volume->SetMapper(mapper);
  volume->SetProperty(property);
  volume->SetUserMatrix(scene.IJKToRAS);
  return volume;
}

/// Reading a pixel waits for the GPU to finish the frame.
void Finish(vtkRenderWindow* window)
{
  vtkNew<vtkUnsignedCharArray> pixel;
  window->GetRGBACharPixelData(0, 0, 0, 0, 1, pixel);
}

double Seconds(const std::function<void()>& work)
{
  const auto start = std::chrono::steady_clock::now();
  work();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

double Median(std::vector<double> values)
{
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

/// Median of full frames, the camera turning half a degree before each so
/// that nothing is reused; the first frame (uploads, shader builds) is left out.
double FrameTime(vtkRenderWindow* window, vtkRenderer* renderer, int repeats)
{
  window->Render();
  Finish(window);
  std::vector<double> times;
  for (int n = 0; n < repeats; ++n)
  {
    renderer->GetActiveCamera()->Azimuth(0.5);
    renderer->ResetCameraClippingRange();
    times.push_back(Seconds([&] {
      window->Render();
      Finish(window);
    }));
  }
  return Median(times);
}

struct Agreement
{
  int HitMaskMismatch = 0;
  double DepthMaxDifference = 0.0;
  double ColorMaxDifference = 0.0;
  double FractionOver2Of255 = 0.0;
  int Hits = 0;
};

void ReadBuffers(vtkRenderWindow* window, int size, std::vector<float>& depth, std::vector<float>& rgba)
{
  depth.resize(static_cast<size_t>(size) * size);
  rgba.resize(static_cast<size_t>(size) * size * 4);
  window->GetZbufferData(0, 0, size - 1, size - 1, depth.data());
  vtkNew<vtkFloatArray> colors;
  window->GetRGBAPixelData(0, 0, size - 1, size - 1, 1, colors);
  std::copy(colors->GetPointer(0), colors->GetPointer(0) + rgba.size(), rgba.begin());
}

/// The same view drawn by both paths, compared in the window's buffers.
Agreement CompareGPUWithCPU(CutCube& scene, int size, std::string& gpuPathUsed, std::string& renderer_name)
{
  vtkNew<vtkRenderWindow> window;
  window->SetOffScreenRendering(1);
  window->SetSize(size, size);
  vtkNew<vtkRenderer> renderer;
  window->AddRenderer(renderer);
  std::vector<float> depth[2];
  std::vector<float> rgba[2];
  const int paths[2] = { vtkVolumeCutVolumeMapper::GPUPath, vtkVolumeCutVolumeMapper::CPUPath };
  for (int p = 0; p < 2; ++p)
  {
    auto volume = OurVolume(scene, paths[p]);
    // This compares what the paths draw, not how fast the program builds: an
    // ASan run beside other tests took 44.9 s on llvmpipe, over the product's
    // 10 s limit, and the mapper rightly drew on the CPU. The full benchmark
    // times the build itself.
    vtkVolumeCutVolumeMapper::SafeDownCast(volume->GetMapper())->SetProgramBuildTimeLimit(600.0);
    renderer->AddVolume(volume);
    if (p == 0)
    {
      renderer->ResetCamera();
      renderer->GetActiveCamera()->Azimuth(30.0);
      renderer->GetActiveCamera()->Elevation(25.0);
      renderer->ResetCameraClippingRange();
    }
    window->Render();
    ReadBuffers(window, size, depth[p], rgba[p]);
    if (p == 0)
    {
      gpuPathUsed = vtkVolumeCutVolumeMapper::SafeDownCast(volume->GetMapper())->GetLastRenderPathAsString();
      auto* openGLWindow = vtkOpenGLRenderWindow::SafeDownCast(window);
      renderer_name = openGLWindow ? openGLWindow->ReportCapabilities() : std::string();
      const size_t line = renderer_name.find("OpenGL renderer string:");
      renderer_name = line == std::string::npos ? "unknown" : renderer_name.substr(line + 24, renderer_name.find('\n', line) - line - 24);
    }
    renderer->RemoveVolume(volume);
  }
  Agreement agreement;
  int over = 0;
  for (size_t pixel = 0; pixel < depth[0].size(); ++pixel)
  {
    const bool hit0 = depth[0][pixel] < 1.0f;
    const bool hit1 = depth[1][pixel] < 1.0f;
    agreement.HitMaskMismatch += hit0 != hit1;
    agreement.Hits += hit1;
    if (hit0 && hit1)
    {
      agreement.DepthMaxDifference = std::max(agreement.DepthMaxDifference, double(std::abs(depth[0][pixel] - depth[1][pixel])));
    }
    double largest = 0.0;
    for (int c = 0; c < 4; ++c)
    {
      largest = std::max(largest, double(std::abs(rgba[0][4 * pixel + c] - rgba[1][4 * pixel + c])));
    }
    agreement.ColorMaxDifference = std::max(agreement.ColorMaxDifference, largest);
    over += largest > 2.0 / 255.0;
  }
  agreement.FractionOver2Of255 = double(over) / depth[0].size();
  return agreement;
}

std::string Quote(const std::string& text)
{
  std::string quoted = "\"";
  for (char c : text)
  {
    if (c == '"' || c == '\\')
    {
      quoted += '\\';
    }
    quoted += c;
  }
  return quoted + "\"";
}

void Report(FILE* out, const std::string& name, double value, const std::string& unit, const std::string& baselineName, double baseline,
  const std::string& details = "{}")
{
  std::string line = "{\"name\": " + Quote(name) + ", \"value\": " + std::to_string(value) + ", \"unit\": " + Quote(unit) +
    ", \"baseline_name\": " + Quote(baselineName) + ", \"baseline_value\": " + std::to_string(baseline) +
    ", \"ratio\": " + (baseline != 0.0 ? std::to_string(value / baseline) : std::string("null")) + ", \"details\": " + details + "}\n";
  std::fputs(line.c_str(), stdout);
  if (out)
  {
    std::fputs(line.c_str(), out);
  }
  std::fflush(stdout);
}

bool Check(CutCube& scene, int size, FILE* out)
{
  std::string used;
  std::string rendererName;
  const Agreement agreement = CompareGPUWithCPU(scene, size, used, rendererName);
  char details[512];
  std::snprintf(details, sizeof(details),
    "{\"renderer\": %s, \"gpu_path_used\": %s, \"hit_pixels\": %d, \"hit_mask_mismatch_pixels\": %d, \"depth_max_abs_difference\": %g, "
    "\"color_max_abs_difference\": %g}",
    Quote(rendererName).c_str(), Quote(used).c_str(), agreement.Hits, agreement.HitMaskMismatch, agreement.DepthMaxDifference,
    agreement.ColorMaxDifference);
  Report(out,
    "OpenGL vs CPU path, " + std::to_string(scene.Dimensions) + "^3, " + std::to_string(size) + "^2: fraction of pixels whose colour differs by more than 2/255",
    agreement.FractionOver2Of255, "fraction", "tolerance", 0.005, details);
  // Tolerances as in the Python test: silhouettes may differ by a pixel's
  // worth of rounding on a few pixels, never by more.
  const bool pass = used == "GPU" && agreement.Hits > 0 && agreement.HitMaskMismatch <= std::max(4, agreement.Hits / 1000) &&
    agreement.DepthMaxDifference < 1e-4 && agreement.FractionOver2Of255 <= 0.005;
  if (!pass)
  {
    std::fprintf(stderr, "GPU and CPU paths disagree (path used: %s, renderer: %s)\n", used.c_str(), rendererName.c_str());
  }
  return pass;
}

void Benchmark(CutCube& scene, int width, int height, bool segments, int repeats, bool withCPUPath, const std::string& cacheRoot,
  FILE* out)
{
  vtkNew<vtkRenderWindow> window;
  window->SetOffScreenRendering(1);
  window->SetSize(width, height);
  vtkNew<vtkRenderer> renderer;
  window->AddRenderer(renderer);
  auto setView = [&] {
    renderer->ResetCamera();
    renderer->GetActiveCamera()->Azimuth(30.0);
    renderer->GetActiveCamera()->Elevation(25.0);
    renderer->ResetCameraClippingRange();
  };
  const std::string setting = std::to_string(scene.Dimensions) + "^3 cut cube" + (segments ? " with 10 segments" : "") + ", " +
    std::to_string(width) + " x " + std::to_string(height);
  auto stock = StockVolume(scene);
  renderer->AddVolume(stock);
  setView();
  const double stockTime = FrameTime(window, renderer, repeats);
  renderer->RemoveVolume(stock);
  stock = nullptr;
  const std::string stockName = "vtkGPUVolumeRayCastMapper iso-surface on the CT masked by the cut, same data, view and process";

  std::vector<int> paths = { vtkVolumeCutVolumeMapper::GPUPath };
  if (withCPUPath)
  {
    paths.push_back(vtkVolumeCutVolumeMapper::CPUPath);
  }
  for (int path : paths)
  {
    auto volume = OurVolume(scene, path, segments);
    auto* mapper = vtkVolumeCutVolumeMapper::SafeDownCast(volume->GetMapper());
    renderer->AddVolume(volume);
    setView();
    if (path == vtkVolumeCutVolumeMapper::GPUPath && !cacheRoot.empty())
    {
      // The first GPU image with our program cache empty (a folder of its
      // own per setting): uploads and the program build included. Where the
      // driver builds in parallel the CPU image is drawn meanwhile, so the
      // frames until the GLSL path draws are counted in.
      const std::string cache = cacheRoot + "/programs-" + std::to_string(scene.Dimensions) + "-" + std::to_string(width) + "x" +
        std::to_string(height) + (segments ? "-segments" : "");
      mapper->SetProgramCacheDirectory(cache.c_str());
      int frames = 0;
      const double firstImage = Seconds([&] {
        do
        {
          window->Render();
          Finish(window);
          ++frames;
        } while (mapper->GetLastRenderPath() != vtkVolumeCutVolumeMapper::GPUPath && frames < 600 &&
          mapper->GetOpenGLRayCaster()->GetProgramStatus() == vtkVolumeCutOpenGLRayCaster::ProgramPending);
      });
      Report(out, "first GPU image including the program build (our program cache empty), " + setting, firstImage, "s",
        "issue 12's target", 2.0,
        "{\"frames\": " + std::to_string(frames) + ", \"path\": " + Quote(mapper->GetLastRenderPathAsString()) +
          ", \"fallback_reason\": " + Quote(mapper->GetGPUFallbackReason()) +
          ", \"program_build_s\": " + std::to_string(mapper->GetLastProgramBuildTime()) + "}");
    }
    const double time = FrameTime(window, renderer, path == vtkVolumeCutVolumeMapper::GPUPath ? repeats : std::max(3, repeats / 3));
    const std::string used = mapper->GetLastRenderPathAsString();
    Report(out, std::string("frame time, ") + (path == vtkVolumeCutVolumeMapper::GPUPath ? "OpenGL" : "CPU") + " path (used: " + used + "), " + setting, time, "s",
      stockName, stockTime, "{\"fallback_reason\": " + Quote(mapper->GetGPUFallbackReason() ? mapper->GetGPUFallbackReason() : "") + "}");
    // One 5 mm burr stroke moving 0.5 mm on the top face, then the frame:
    // the changed bricks are uploaded (GPU) or the pixels over them recast (CPU).
    std::vector<double> strokeFrames;
    std::vector<double> mapperShare;
    const double top = scene.Center + scene.Half;
    for (int n = 0; n < std::max(9, repeats); ++n)
    {
      const double offset = (n - 4) * 0.08 * scene.Half;
      const double p0[3] = { scene.Center + offset, scene.Center - offset, top };
      const double p1[3] = { p0[0] + 0.5, p0[1], top };
      scene.Cut->CutCapsule(p0, p1, 2.5);
      strokeFrames.push_back(Seconds([&] {
        window->Render();
        Finish(window);
      }));
      mapperShare.push_back(mapper->GetLastFrameTime());
    }
    Report(out, std::string("whole frame after one 5 mm burr stroke, ") + (path == vtkVolumeCutVolumeMapper::GPUPath ? "OpenGL" : "CPU") + " path (used: " + used + "), " + setting,
      Median(strokeFrames), "s", "full frame of the same path and view", time,
      "{\"mapper_part_median_s\": " + std::to_string(Median(mapperShare)) + "}");
    renderer->RemoveVolume(volume);
  }
}
} // namespace

int vtkVolumeCutVolumeMapperBenchmark(int argc, char* argv[])
{
  const bool gpuOnly = argc > 2 && std::strcmp(argv[2], "gpu") == 0;
  const bool full = gpuOnly || (argc > 2 && std::strcmp(argv[2], "full") == 0);
  FILE* out = nullptr;
  if (full && argc > 1)
  {
    out = std::fopen((std::string(argv[1]) + "/mapper_hardware.jsonl").c_str(), "w");
  }
  bool pass = true;
  if (!full)
  {
    CutCube scene(48);
    pass = Check(scene, 128, out);
  }
  else
  {
    const int repeats = argc > 3 ? std::max(1, std::atoi(argv[3])) : 15;
    // A fourth argument replaces the table's volumes by one of that size (a
    // quick run on a software rasterizer).
    const std::vector<int> volumes = argc > 4 ? std::vector<int>{ std::max(16, std::atoi(argv[4])) } : std::vector<int>{ 256, 512 };
    for (int dimensions : volumes)
    {
      CutCube scene(dimensions);
      pass = Check(scene, 512, out) && pass;
      for (int size : { 512, 1024 })
      {
        Benchmark(scene, size, size, false, repeats, !gpuOnly, argv[1], out);
      }
      Benchmark(scene, 1920, 1080, false, repeats, !gpuOnly, argv[1], out);
      Benchmark(scene, 1920, 1080, true, repeats, !gpuOnly, argv[1], out);
    }
  }
  if (out)
  {
    std::fclose(out);
  }
  return pass ? 0 : 1;
}
