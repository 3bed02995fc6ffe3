// The stepnc commands, one file each: each adds its subcommand to the
// application and reports its exit code through `setResult`.
#pragma once

#include <functional>

namespace CLI {
class App;
}

namespace stepnc::tool {

void registerCompile(CLI::App &app, std::function<void(int)> setResult);
void registerCheck(CLI::App &app, std::function<void(int)> setResult);
void registerConvert(CLI::App &app, std::function<void(int)> setResult);
void registerSchema(CLI::App &app, std::function<void(int)> setResult);
void registerOpt(CLI::App &app, std::function<void(int)> setResult);
void registerSim(CLI::App &app, std::function<void(int)> setResult);

} // namespace stepnc::tool
