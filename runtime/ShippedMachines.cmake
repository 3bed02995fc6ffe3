# Writes OUT, a C++ file holding the text of every machines/*.toml as
# runtime::kShippedMachines, so that `--machine hsc-3axis` works wherever
# stepnc is installed. Run as: cmake -DDIR=... -DOUT=... -P ShippedMachines.cmake
file(GLOB files "${DIR}/*.toml")
list(SORT files)
set(body "// Generated from machines/*.toml by runtime/ShippedMachines.cmake; do not edit.\n#include <string>\n#include <utility>\n#include <vector>\n\nnamespace stepnc::runtime {\nextern const std::vector<std::pair<std::string, std::string>> kShippedMachines;\nconst std::vector<std::pair<std::string, std::string>> kShippedMachines = {\n")
foreach(f ${files})
  get_filename_component(name "${f}" NAME_WE)
  file(READ "${f}" text)
  string(APPEND body "  {\"${name}\", R\"stepnc_toml(${text})stepnc_toml\"},\n")
endforeach()
string(APPEND body "};\n} // namespace stepnc::runtime\n")
file(WRITE "${OUT}.tmp" "${body}")
execute_process(COMMAND ${CMAKE_COMMAND} -E copy_if_different "${OUT}.tmp" "${OUT}")
