# lit configuration for stepnc's golden tests.
#
# Tests are *.test files, Part 21 inputs (*.p21) and IR text (*.ir) carrying their own RUN
# lines. Tests that read the third-party sample corpus say `REQUIRES: corpus`;
# the corpus is found at $STEPNC_CORPUS, else at the path given to CMake
# (STEPNC_CORPUS_DIR, default ../shared/corpus beside the checkout). When it
# is absent those tests are reported UNSUPPORTED and a note says so.
import os

import lit.formats

config.name = "stepnc"
config.test_format = lit.formats.ShTest(execute_external=True)
config.suffixes = [".test", ".p21", ".ir"]
config.test_source_root = os.path.dirname(__file__)
config.test_exec_root = os.path.join(config.stepnc_obj_root, "tests")
config.excludes = ["Inputs", "unit", "fuzz", "CMakeLists.txt", "lit.cfg.py", "update-corpus-checks.py"]
# Helper scripts beside tests (foo.test.sh) are not tests themselves.

config.environment["PATH"] = os.pathsep.join(
    [config.stepnc_tools_dir, config.llvm_tools_dir, config.environment.get("PATH", os.environ["PATH"])])
# Every pass run by a test is followed by the IR verifier.
config.environment["STEPNC_VERIFY_EACH"] = "1"
for var in ("ASAN_OPTIONS", "UBSAN_OPTIONS"):
    if var in os.environ:
        config.environment[var] = os.environ[var]

# The sanitizer build (scripts/build.sh --sanitize) runs every test but the
# sweeps that put the whole corpus through the whole pipeline once more for
# another reader or target: they say `UNSUPPORTED: sanitizer` and run in the
# Release build only (docs/testing.md, "What the sanitizer build runs").
if config.stepnc_sanitize == "ON":
    config.available_features.add("sanitizer")

corpus = os.path.abspath(os.environ.get("STEPNC_CORPUS") or config.corpus_dir)
if os.path.isdir(corpus):
    config.available_features.add("corpus")
else:
    lit_config.warning(
        "sample corpus not found at %s: tests that need it are UNSUPPORTED (skipped); "
        "set STEPNC_CORPUS or -DSTEPNC_CORPUS_DIR to run them" % corpus)

import shutil

# libxml2's xmllint validates Part 28 files against the generated XSDs.
if shutil.which("xmllint"):
    config.available_features.add("xmllint")
else:
    lit_config.warning("xmllint is not installed: the Part 28 XSD checks are UNSUPPORTED (skipped); "
                       "scripts/install-deps.sh installs it (libxml2-utils)")

# LinuxCNC's standalone interpreter checks the rs274 target's programs.
if shutil.which("rs274"):
    config.available_features.add("rs274")
else:
    lit_config.warning("LinuxCNC's rs274 interpreter is not installed: the rs274 target's checks are "
                       "UNSUPPORTED (skipped); scripts/install-deps.sh installs it (linuxcnc-uspace)")
config.substitutions.append(("%check-rs274", "python3 %s --stepnc %s" % (
    os.path.join(config.test_source_root, "backends", "check-rs274.py"),
    os.path.join(config.stepnc_tools_dir, "stepnc"))))
# A lathe's native motion checked against its toolpath IR, played independently.
config.substitutions.append(("%check-native-lathe", "python3 %s --stepnc %s" % (
    os.path.join(config.test_source_root, "backends", "check-native-lathe.py"),
    os.path.join(config.stepnc_tools_dir, "stepnc"))))
# The flanks a program leaves on a boss whose walls lean in, measured independently.
config.substitutions.append(("%check-sloped-flanks", "python3 %s" % (
    os.path.join(config.test_source_root, "passes", "expand-strategies", "check-sloped-flanks.py"))))
# Open CASCADE's STEP reader reads the STEP-NC that compile --emit=stepnc writes.
occt_read_step = os.path.join(config.stepnc_tools_dir, "stepnc-occt-read-step")
if config.occt_available == "ON" and os.path.exists(occt_read_step):
    config.available_features.add("occt")
else:
    lit_config.warning("Open CASCADE is not installed: reading written STEP-NC with its STEP reader is "
                       "UNSUPPORTED (skipped); scripts/install-deps.sh installs it (libocct-data-exchange-dev)")
config.substitutions.append(("%occt-read-step", occt_read_step))
config.substitutions.append(("%stepnc", os.path.join(config.stepnc_tools_dir, "stepnc")))
config.substitutions.append(("%corpus", corpus))
config.substitutions.append(("%inputs", os.path.join(config.test_source_root, "Inputs")))
config.substitutions.append(("%examples", os.path.join(config.stepnc_src_root, "examples")))
