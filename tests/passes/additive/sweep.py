#!/usr/bin/env python3
"""Compiles variants of the channel block (examples/channel-block.stp) with
the bead, overlap, allowance, draft, strategy and layer changed together, and
checks that every one compiles to a toolpath IR the deposition check passes
(it runs in verify-toolpaths: an uncovered point, overflow, a bead in the
channel or the energy on in a rapid fail the compile). One line per variant;
exit status 1 when any fails."""
import itertools
import os
import re
import subprocess
import sys
import tempfile

stepnc, example = sys.argv[1], sys.argv[2]
text = open(example).read()

# (bead width, bead height = layer, overlap, allowance)
beads = [(1.2, 0.4, 0.25, 0.4), (2.0, 0.5, 0.3, 0.5), (3.0, 1.0, 0.4, 1.0)]
drafts = ["$", "10.", "-5."]
strategies = [".CONTOUR_THEN_INFILL.,2,.ZIGZAG.,45.,90.", ".CONTOUR_ONLY.,$,$,$,$",
              ".CONTOUR_THEN_INFILL.,1,.PARALLEL.,30.,67."]
failed = 0
with tempfile.TemporaryDirectory() as work:
    for n, ((w, h, o, a), draft, strategy) in enumerate(itertools.product(beads, drafts, strategies)):
        t = text
        t = re.sub(r"#43=DEPOSITION_TECHNOLOGY\(0\.01,\.TCP\.,800\.,#44,2\.,0\.5,0\.3,",
                   "#43=DEPOSITION_TECHNOLOGY(0.01,.TCP.,800.,#44,%g,%g,%g," % (w, h, o), t)
        t = re.sub(r"#40=DEPOSITION_OPERATION\(\$,\$,'deposit block',#41,0\.5,\$,\$,#42,#43,#47,0\.5\);",
                   "#40=DEPOSITION_OPERATION($,$,'deposit block',#41,%g,$,$,#42,#43,#47,%g);" % (h, a), t)
        t = re.sub(r"#20=AM_EXTRUDED_FEATURE\((.*),20\.,\$,\(#30\)\);",
                   lambda m: "#20=AM_EXTRUDED_FEATURE(%s,20.,%s,(#30));" % (m.group(1), draft), t)
        t = re.sub(r"#47=DEPOSITION_STRATEGY\(\.CONTOUR_THEN_INFILL\.,2,\.ZIGZAG\.,45\.,90\.,",
                   "#47=DEPOSITION_STRATEGY(%s," % strategy, t)
        path = os.path.join(work, "v%d.stp" % n)
        with open(path, "w") as f:
            f.write(t)
        r = subprocess.run([stepnc, "compile", path, "--emit=toolpath-ir", "--no-adapt-feed",
                            "--no-compensate-deflection", "-o", os.path.join(work, "v.ir")],
                           capture_output=True, text=True)
        name = "bead %g x %g, overlap %g, allowance %g, draft %s, %s" % (w, h, o, a, draft, strategy)
        errors = [line for line in r.stderr.splitlines() if ": error:" in line]
        if r.returncode != 0 or errors:
            failed += 1
            print("FAIL: %s: %s" % (name, errors[0] if errors else r.stderr.strip()[:300]))
        else:
            print("ok: %s" % name)
print("%d variants, %d failed" % (n + 1, failed))
sys.exit(1 if failed else 0)
