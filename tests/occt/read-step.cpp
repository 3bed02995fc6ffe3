// read-step FILE...: reads each file with Open CASCADE's STEP reader
// (STEPControl_Reader::ReadFile) and prints one line per file: "ok: NAME"
// when ReadFile returns IFSelect_RetDone, else "error: NAME: <status>".
// Exit status 0 when every file was read. OCCT's STEP reader is made for
// AP203/AP214/AP242 geometry; it reads any Part 21 file's syntax and
// instances, and stepnc's tests use it as an independent Part 21 reader of the
// machine-optimised STEP-NC files stepnc writes (docs/feedback.md).
#include <IFSelect_ReturnStatus.hxx>
#include <Interface_InterfaceModel.hxx>
#include <STEPControl_Reader.hxx>

#include <cstdio>

namespace {

const char *statusName(IFSelect_ReturnStatus status) {
  switch (status) {
  case IFSelect_RetVoid:
    return "IFSelect_RetVoid (nothing read)";
  case IFSelect_RetDone:
    return "IFSelect_RetDone";
  case IFSelect_RetError:
    return "IFSelect_RetError";
  case IFSelect_RetFail:
    return "IFSelect_RetFail";
  case IFSelect_RetStop:
    return "IFSelect_RetStop";
  }
  return "unknown status";
}

} // namespace

int main(int argc, char **argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s FILE...\n", argv[0]);
    return 2;
  }
  int failed = 0;
  for (int i = 1; i < argc; ++i) {
    STEPControl_Reader reader;
    const IFSelect_ReturnStatus status = reader.ReadFile(argv[i]);
    if (status == IFSelect_RetDone) {
      std::printf("ok: %s: %d entities\n", argv[i], reader.Model()->NbEntities());
    } else {
      std::printf("error: %s: %s\n", argv[i], statusName(status));
      ++failed;
    }
  }
  return failed == 0 ? 0 : 1;
}
