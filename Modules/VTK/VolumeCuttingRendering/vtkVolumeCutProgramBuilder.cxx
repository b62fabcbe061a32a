// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutProgramBuilder.h"

#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkOpenGLRenderWindow.h>
#include <vtkOpenGLShaderCache.h>
#include <vtkShaderProgram.h>
#include <vtkTimerLog.h>
#include <vtk_glad.h>
#include <vtksys/FStream.hxx>
#include <vtksys/MD5.h>
#include <vtksys/SystemTools.hxx>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

namespace
{
// VTK's System and Output replacements (version line, fragment outputs),
// reached through its shader cache, so that the program is the one VTK
// would build from the same sources.
class SourcePreparer : public vtkOpenGLShaderCache
{
public:
  static SourcePreparer* New()
  {
    auto* preparer = new SourcePreparer;
    preparer->InitializeObjectBase();
    return preparer;
  }
  vtkTypeMacro(SourcePreparer, vtkOpenGLShaderCache);
  unsigned int Prepare(std::string& vertex, std::string& fragment)
  {
    std::string geometry;
    std::string tessControl;
    std::string tessEvaluation;
    return this->ReplaceShaderValues(vertex, fragment, geometry, tessControl, tessEvaluation);
  }
};

// A vtkShaderProgram around a program handle linked here (from source in
// parallel, or from a binary): uniforms, binding and release as VTK's own.
class AdoptedProgram : public vtkShaderProgram
{
public:
  static AdoptedProgram* New()
  {
    auto* program = new AdoptedProgram;
    program->InitializeObjectBase();
    return program;
  }
  vtkTypeMacro(AdoptedProgram, vtkShaderProgram);
  void Adopt(unsigned int handle)
  {
    this->Handle = static_cast<int>(handle);
    this->Linked = true;
    this->Compiled = true;
  }
};

std::string GLString(GLenum name)
{
  const GLubyte* value = glGetString(name);
  return value ? reinterpret_cast<const char*>(value) : "";
}

std::string ShaderLog(GLuint shader)
{
  GLint length = 0;
  glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &length);
  std::string log(static_cast<size_t>(std::max(length, 1)), '\0');
  glGetShaderInfoLog(shader, length, nullptr, &log[0]);
  log.resize(std::strlen(log.c_str()));
  return log;
}

std::string ProgramLog(GLuint program)
{
  GLint length = 0;
  glGetProgramiv(program, GL_INFO_LOG_LENGTH, &length);
  std::string log(static_cast<size_t>(std::max(length, 1)), '\0');
  glGetProgramInfoLog(program, length, nullptr, &log[0]);
  log.resize(std::strlen(log.c_str()));
  return log;
}

// The lines of a driver's log that say what is wrong (its errors, without
// the warnings), short enough to read in a log line.
std::string Errors(const std::string& log)
{
  std::string errors;
  size_t start = 0;
  while (start < log.size())
  {
    size_t end = log.find('\n', start);
    end = end == std::string::npos ? log.size() : end;
    const std::string line = log.substr(start, end - start);
    if (line.find("error") != std::string::npos || line.find("ERROR") != std::string::npos)
    {
      errors += (errors.empty() ? "" : "; ") + line;
    }
    start = end + 1;
  }
  errors = errors.empty() ? log : errors;
  return errors.size() > 400 ? errors.substr(0, 400) + "..." : errors;
}

std::string MD5(const std::string& text)
{
  vtksysMD5* md5 = vtksysMD5_New();
  vtksysMD5_Initialize(md5);
  vtksysMD5_Append(md5, reinterpret_cast<const unsigned char*>(text.data()), static_cast<int>(text.size()));
  unsigned char digest[16];
  vtksysMD5_Finalize(md5, digest);
  vtksysMD5_Delete(md5);
  char hex[33];
  vtksysMD5_DigestToHex(digest, hex);
  hex[32] = '\0';
  return hex;
}

// Cache file layout: magic, the key's length and the key (sources and
// driver: a file of another program or driver is told apart even if two
// keys' hashes met), the binary format, the payload's length and MD5, the payload.
const char CacheMagic[8] = { 'V', 'C', 'P', 'R', 'O', 'G', '0', '1' };
}

//------------------------------------------------------------------------------
vtkVolumeCutProgramBuilder::vtkVolumeCutProgramBuilder() = default;

//------------------------------------------------------------------------------
vtkVolumeCutProgramBuilder::~vtkVolumeCutProgramBuilder()
{
  // The owner releases with its context current; a handle still held here
  // belongs to a context gone already.
  this->Abandon();
}

//------------------------------------------------------------------------------
bool vtkVolumeCutProgramBuilder::HasParallelCompile()
{
  return GLAD_GL_KHR_parallel_shader_compile || GLAD_GL_ARB_parallel_shader_compile;
}

//------------------------------------------------------------------------------
int vtkVolumeCutProgramBuilder::NumberOfBinaryFormats()
{
  if (!glGetProgramBinary || !glProgramBinary)
  {
    return 0;
  }
  GLint formats = 0;
  glGetIntegerv(GL_NUM_PROGRAM_BINARY_FORMATS, &formats);
  return formats;
}

//------------------------------------------------------------------------------
std::string vtkVolumeCutProgramBuilder::DriverDescription()
{
  return GLString(GL_RENDERER) + ", OpenGL " + GLString(GL_VERSION) + " (" + GLString(GL_VENDOR) + ")";
}

//------------------------------------------------------------------------------
std::string vtkVolumeCutProgramBuilder::DefaultCacheDirectory()
{
  std::string base;
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"))
  {
    base = xdg;
  }
#ifdef _WIN32
  if (base.empty())
  {
    if (const char* local = std::getenv("LOCALAPPDATA"))
    {
      base = local;
    }
  }
#endif
  if (base.empty())
  {
    if (const char* home = std::getenv("HOME"))
    {
      base = std::string(home) + "/.cache";
    }
  }
  return base.empty() ? std::string() : base + "/VolumeCutting/programs";
}

//------------------------------------------------------------------------------
vtkShaderProgram* vtkVolumeCutProgramBuilder::GetProgram() const
{
  return this->State == Ready ? this->Program.GetPointer() : nullptr;
}

//------------------------------------------------------------------------------
double vtkVolumeCutProgramBuilder::GetBuildSeconds() const
{
  return this->State == Pending ? vtkTimerLog::GetUniversalTime() - this->StartTime : this->BuildSeconds;
}

//------------------------------------------------------------------------------
std::string vtkVolumeCutProgramBuilder::CacheFile() const
{
  return this->CacheDirectory.empty() ? std::string() : this->CacheDirectory + "/" + MD5(this->Key) + ".bin";
}

//------------------------------------------------------------------------------
vtkVolumeCutProgramBuilder::Status vtkVolumeCutProgramBuilder::Start(vtkOpenGLRenderWindow* window, const std::string& vertexSource,
  const std::string& fragmentSource, const std::string& cacheDirectory)
{
  this->Release(window);
  this->Window = window;
  this->FragmentSource = fragmentSource;
  this->CacheDirectory = cacheDirectory;
  this->CacheWarning.clear();
  this->Error.clear();
  this->LoadedFromCache = false;
  this->StoredInCache = false;
  this->StartTime = vtkTimerLog::GetUniversalTime();

  std::string vertex = vertexSource;
  std::string fragment = fragmentSource;
  vtkNew<SourcePreparer> preparer;
  const unsigned int outputs = preparer->Prepare(vertex, fragment);
  this->Key = vertex + '\0' + fragment + '\0' + GLString(GL_VENDOR) + '\0' + GLString(GL_RENDERER) + '\0' + GLString(GL_VERSION) +
    '\0' + GLString(GL_SHADING_LANGUAGE_VERSION);

  this->Handle = glCreateProgram();
  if (this->Handle == 0)
  {
    this->Error = "glCreateProgram failed (is the context lost?)";
    this->State = Failed;
    this->BuildSeconds = vtkTimerLog::GetUniversalTime() - this->StartTime;
    return this->State;
  }
  if (this->LoadBinary())
  {
    return this->Finish();
  }

  // From source: submit both compiles and the link; with parallel compile
  // none of these waits, and the status queries are left to Poll.
  if (GLAD_GL_KHR_parallel_shader_compile && glMaxShaderCompilerThreadsKHR)
  {
    glMaxShaderCompilerThreadsKHR(0xFFFFFFFFu); // as many as the driver likes
  }
  else if (GLAD_GL_ARB_parallel_shader_compile && glMaxShaderCompilerThreadsARB)
  {
    glMaxShaderCompilerThreadsARB(0xFFFFFFFFu);
  }
  this->VertexShader = glCreateShader(GL_VERTEX_SHADER);
  this->FragmentShader = glCreateShader(GL_FRAGMENT_SHADER);
  const char* vertexText = vertex.c_str();
  const char* fragmentText = fragment.c_str();
  glShaderSource(this->VertexShader, 1, &vertexText, nullptr);
  glShaderSource(this->FragmentShader, 1, &fragmentText, nullptr);
  glCompileShader(this->VertexShader);
  glCompileShader(this->FragmentShader);
  glAttachShader(this->Handle, this->VertexShader);
  glAttachShader(this->Handle, this->FragmentShader);
  for (unsigned int output = 0; output < outputs; ++output)
  {
    glBindFragDataLocation(this->Handle, output, ("fragOutput" + std::to_string(output)).c_str());
  }
  if (NumberOfBinaryFormats() > 0 && !this->CacheDirectory.empty())
  {
    glProgramParameteri(this->Handle, GL_PROGRAM_BINARY_RETRIEVABLE_HINT, GL_TRUE);
  }
  glLinkProgram(this->Handle);
  this->State = Pending;
  return this->Poll();
}

//------------------------------------------------------------------------------
vtkVolumeCutProgramBuilder::Status vtkVolumeCutProgramBuilder::Poll()
{
  if (this->State != Pending)
  {
    return this->State;
  }
  if (HasParallelCompile())
  {
    GLint complete = GL_FALSE;
    glGetProgramiv(this->Handle, GL_COMPLETION_STATUS_KHR, &complete);
    if (!complete)
    {
      return this->State;
    }
  }
  return this->Finish();
}

//------------------------------------------------------------------------------
vtkVolumeCutProgramBuilder::Status vtkVolumeCutProgramBuilder::Finish()
{
  GLint linked = GL_FALSE;
  glGetProgramiv(this->Handle, GL_LINK_STATUS, &linked);
  if (!linked)
  {
    GLint compiled = GL_TRUE;
    if (this->FragmentShader)
    {
      glGetShaderiv(this->FragmentShader, GL_COMPILE_STATUS, &compiled);
    }
    this->Error = !compiled ? "the fragment shader does not compile: " + Errors(ShaderLog(this->FragmentShader))
                            : "the program does not link: " + Errors(ProgramLog(this->Handle));
    if (this->VertexShader)
    {
      glGetShaderiv(this->VertexShader, GL_COMPILE_STATUS, &compiled);
      if (!compiled)
      {
        this->Error = "the vertex shader does not compile: " + Errors(ShaderLog(this->VertexShader));
      }
    }
  }
  // The shaders' work is in the program now.
  for (unsigned int* shader : { &this->VertexShader, &this->FragmentShader })
  {
    if (*shader)
    {
      glDetachShader(this->Handle, *shader);
      glDeleteShader(*shader);
      *shader = 0;
    }
  }
  this->BuildSeconds = vtkTimerLog::GetUniversalTime() - this->StartTime;
  if (!linked)
  {
    glDeleteProgram(this->Handle);
    this->Handle = 0;
    this->State = Failed;
    return this->State;
  }
  auto program = vtkSmartPointer<AdoptedProgram>::New();
  program->Adopt(this->Handle);
  this->Program = program;
  this->State = Ready;
  if (!this->LoadedFromCache)
  {
    this->StoreBinary();
  }
  return this->State;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutProgramBuilder::LoadBinary()
{
  const std::string path = this->CacheFile();
  if (path.empty() || NumberOfBinaryFormats() <= 0 || !vtksys::SystemTools::FileExists(path, true))
  {
    return false;
  }
  auto refuse = [this, &path](const std::string& why) {
    this->CacheWarning = "the cached GPU program " + path + " is " + why + "; it is removed and the program rebuilt from source";
    vtksys::SystemTools::RemoveFile(path);
    return false;
  };
  vtksys::ifstream in(path.c_str(), std::ios::binary);
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  size_t offset = 0;
  auto read = [&bytes, &offset](void* destination, size_t size) {
    if (offset + size > bytes.size())
    {
      return false;
    }
    std::memcpy(destination, bytes.data() + offset, size);
    offset += size;
    return true;
  };
  char magic[sizeof(CacheMagic)];
  std::uint64_t keyLength = 0;
  if (!read(magic, sizeof(magic)) || std::memcmp(magic, CacheMagic, sizeof(magic)) != 0 || !read(&keyLength, sizeof(keyLength)))
  {
    return refuse("not a program binary of this version (truncated or corrupt)");
  }
  if (keyLength != this->Key.size() || offset + keyLength > bytes.size() ||
    std::memcmp(bytes.data() + offset, this->Key.data(), this->Key.size()) != 0)
  {
    return refuse("of another program or driver");
  }
  offset += keyLength;
  std::uint32_t format = 0;
  std::uint64_t length = 0;
  char digest[33] = {};
  if (!read(&format, sizeof(format)) || !read(&length, sizeof(length)) || !read(digest, 32) || offset + length != bytes.size())
  {
    return refuse("truncated");
  }
  const std::string payload(bytes.data() + offset, static_cast<size_t>(length));
  if (MD5(payload) != std::string(digest, 32))
  {
    return refuse("corrupt (checksum mismatch)");
  }
  glProgramBinary(this->Handle, format, payload.data(), static_cast<GLsizei>(length));
  GLint linked = GL_FALSE;
  glGetProgramiv(this->Handle, GL_LINK_STATUS, &linked);
  if (!linked)
  {
    // A program object stays usable for a build from source after a refused binary.
    return refuse("refused by the driver");
  }
  this->LoadedFromCache = true;
  return true;
}

//------------------------------------------------------------------------------
void vtkVolumeCutProgramBuilder::StoreBinary()
{
  const std::string path = this->CacheFile();
  if (path.empty() || NumberOfBinaryFormats() <= 0)
  {
    return;
  }
  GLint length = 0;
  glGetProgramiv(this->Handle, GL_PROGRAM_BINARY_LENGTH, &length);
  if (length <= 0)
  {
    return;
  }
  std::string payload(static_cast<size_t>(length), '\0');
  GLenum format = 0;
  GLsizei written = 0;
  glGetProgramBinary(this->Handle, length, &written, &format, &payload[0]);
  if (written <= 0)
  {
    return;
  }
  payload.resize(static_cast<size_t>(written));
  if (!vtksys::SystemTools::MakeDirectory(this->CacheDirectory))
  {
    this->CacheWarning = "the program cache folder " + this->CacheDirectory + " cannot be made; programs are built from source each start";
    return;
  }
  // Written aside and renamed: a second process never reads half a file.
  const std::string partial = path + ".partial" + std::to_string(vtksys::SystemTools::GetTime());
  {
    vtksys::ofstream out(partial.c_str(), std::ios::binary | std::ios::trunc);
    const std::uint64_t keyLength = this->Key.size();
    const std::uint32_t format32 = format;
    const std::uint64_t payloadLength = payload.size();
    const std::string digest = MD5(payload);
    out.write(CacheMagic, sizeof(CacheMagic));
    out.write(reinterpret_cast<const char*>(&keyLength), sizeof(keyLength));
    out.write(this->Key.data(), static_cast<std::streamsize>(this->Key.size()));
    out.write(reinterpret_cast<const char*>(&format32), sizeof(format32));
    out.write(reinterpret_cast<const char*>(&payloadLength), sizeof(payloadLength));
    out.write(digest.data(), 32);
    out.write(payload.data(), static_cast<std::streamsize>(payload.size()));
    if (!out.good())
    {
      out.close();
      vtksys::SystemTools::RemoveFile(partial);
      this->CacheWarning = "the GPU program cannot be written to " + this->CacheDirectory;
      return;
    }
  }
  this->StoredInCache = std::rename(partial.c_str(), path.c_str()) == 0;
  if (!this->StoredInCache)
  {
    vtksys::SystemTools::RemoveFile(partial);
  }
}

//------------------------------------------------------------------------------
void vtkVolumeCutProgramBuilder::Release(vtkWindow* window)
{
  if (this->Program)
  {
    // Deletes the handle and unbinds it from the window's shader cache.
    this->Program->ReleaseGraphicsResources(window);
    this->Program = nullptr;
    this->Handle = 0;
  }
  if (this->Handle || this->VertexShader || this->FragmentShader)
  {
    if (this->Window && this->Window->IsCurrent())
    {
      if (this->VertexShader)
      {
        glDeleteShader(this->VertexShader);
      }
      if (this->FragmentShader)
      {
        glDeleteShader(this->FragmentShader);
      }
      if (this->Handle)
      {
        glDeleteProgram(this->Handle);
      }
    }
  }
  this->Handle = this->VertexShader = this->FragmentShader = 0;
  this->State = Empty;
  this->Window = nullptr;
}

//------------------------------------------------------------------------------
void vtkVolumeCutProgramBuilder::Abandon()
{
  if (this->Program)
  {
    // Its handle died with the context: keep VTK from deleting a stranger's.
    static_cast<AdoptedProgram*>(this->Program.GetPointer())->Adopt(0);
    this->Program = nullptr;
  }
  this->Handle = this->VertexShader = this->FragmentShader = 0;
  this->State = Empty;
  this->Window = nullptr;
}
