#include "cad/step.h"

#include <fmt/format.h>
#include <unistd.h>

#include <IFSelect_ReturnStatus.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <Message_PrinterOStream.hxx>
#include <STEPControl_Reader.hxx>
#include <STEPControl_Writer.hxx>
#include <Standard_Failure.hxx>
#include <TopExp_Explorer.hxx>
#include <filesystem>
#include <mutex>
#include <system_error>

#include "core/error.h"

namespace glint::cad {
namespace {

// OCCT's STEP translator keeps global state and prints to stdout: one at a time, silenced.
std::mutex& step_mutex() {
  static std::mutex mutex;
  return mutex;
}

void silence_kernel_messages() {
  static std::once_flag once;
  std::call_once(once, [] {
    Message::DefaultMessenger()->RemovePrinters(STANDARD_TYPE(Message_PrinterOStream));
  });
}

}  // namespace

TopoDS_Shape read_step(const std::string& path) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) throw Error(path, "", "no such file");
  if (std::filesystem::file_size(path, error) == 0) throw Error(path, "", "the file is empty");
  const std::lock_guard lock(step_mutex());
  silence_kernel_messages();
  try {
    STEPControl_Reader reader;
    const IFSelect_ReturnStatus status = reader.ReadFile(path.c_str());
    if (status != IFSelect_RetDone)
      throw Error(path, "", "not a readable STEP file (the reader stopped at its syntax)");
    if (reader.NbRootsForTransfer() == 0)
      throw Error(path, "", "the STEP file holds no shape to transfer");
    reader.TransferRoots();
    const TopoDS_Shape shape = reader.OneShape();
    if (shape.IsNull() || !TopExp_Explorer(shape, TopAbs_FACE).More())
      throw Error(path, "", "the STEP file's shapes have no faces (no surface to label)");
    return shape;
  } catch (const Standard_Failure& e) {
    throw Error(path, "", std::string("STEP translation failed: ") + e.GetMessageString());
  }
}

void write_step(const TopoDS_Shape& shape, const std::string& path) {
  const std::filesystem::path target(path);
  if (target.has_parent_path()) std::filesystem::create_directories(target.parent_path());
  const std::string temporary = fmt::format("{}.tmp-{}.step", path, ::getpid());
  const std::lock_guard lock(step_mutex());
  silence_kernel_messages();
  try {
    STEPControl_Writer writer;
    if (writer.Transfer(shape, STEPControl_AsIs) != IFSelect_RetDone)
      throw Error(path, "", "the shape could not be translated to STEP");
    if (writer.Write(temporary.c_str()) != IFSelect_RetDone) {
      std::filesystem::remove(temporary);
      throw Error(path, "", "could not write the STEP file");
    }
  } catch (const Standard_Failure& e) {
    std::filesystem::remove(temporary);
    throw Error(path, "", std::string("STEP translation failed: ") + e.GetMessageString());
  }
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error) {
    std::filesystem::remove(temporary);
    throw Error(path, "", "could not rename the written file: " + error.message());
  }
}

}  // namespace glint::cad
