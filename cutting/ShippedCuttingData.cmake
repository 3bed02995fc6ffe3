# Writes OUT, a C++ file holding the text of IN (cutting/materials.toml) as
# cutting::kShippedCuttingData, so that the shipped cutting data is in the
# binary wherever stepnc is installed. Run as: cmake -DIN=... -DOUT=... -P ShippedCuttingData.cmake
file(READ "${IN}" text)
set(body "// Generated from cutting/materials.toml by cutting/ShippedCuttingData.cmake; do not edit.\nnamespace stepnc::cutting {\nextern const char *const kShippedCuttingData;\nconst char *const kShippedCuttingData = R\"stepnc_toml(${text})stepnc_toml\";\n} // namespace stepnc::cutting\n")
file(WRITE "${OUT}.tmp" "${body}")
execute_process(COMMAND ${CMAKE_COMMAND} -E copy_if_different "${OUT}.tmp" "${OUT}")
