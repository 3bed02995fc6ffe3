#!/usr/bin/env python3
"""Make a large AP238 AIM toolpath file (edition 1), for benchmarking the AIM
reader: one workplan of STEPS workingsteps, each an operation with PATHS
polyline toolpaths of POINTS points (a zigzag 3 mm below the top), one tool,
one technology, coolant on.

    gen-aim-toolpaths.py OUTPUT.stpnc [--steps 200] [--paths 20] [--points 50]

The units, contexts, project and shared words are those of the project's
test file tests/ap238/aim-mill-toolpath-mm.stpnc (its instances #1 to #61);
everything after them is written here. Only the Python 3 standard library.
"""
import argparse
import os
import re

HERE = os.path.dirname(os.path.abspath(__file__))
TEMPLATE = os.path.join(HERE, "..", "tests", "ap238", "aim-mill-toolpath-mm.stpnc")
LAST_TEMPLATE_ID = 61  # units, contexts, project, workpiece, shared words, security plane (#56)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("output")
    ap.add_argument("--steps", type=int, default=200)
    ap.add_argument("--paths", type=int, default=20)
    ap.add_argument("--points", type=int, default=50)
    args = ap.parse_args()
    with open(TEMPLATE) as f:
        text = f.read()
    header = text[:text.index("DATA;") + len("DATA;")]
    kept = [line for line in text.splitlines()
            if (m := re.match(r"#(\d+)=", line)) and int(m.group(1)) <= LAST_TEMPLATE_ID]
    out = [header.replace("aim-mill-toolpath-mm.stpnc", os.path.basename(args.output))] + kept
    n = [LAST_TEMPLATE_ID]

    def new(entity):
        n[0] += 1
        out.append("#%d=%s;" % (n[0], entity))
        return "#%d" % n[0]

    tech = new("MACHINING_TECHNOLOGY('cut','milling','','')")
    feed = new("MACHINING_FEED_SPEED_REPRESENTATION('feed speed',(#%d),#24)" % (n[0] + 2))
    new("MEASURE_REPRESENTATION_ITEM('feed speed',NUMERIC_MEASURE(600.),#16)")
    new("ACTION_PROPERTY_REPRESENTATION('','',%s,%s)" % (new("ACTION_PROPERTY('feedrate','',%s)" % tech), feed))
    spindle = new("MACHINING_SPINDLE_SPEED_REPRESENTATION('spindle speed',(#%d),#24)" % (n[0] + 2))
    new("MEASURE_REPRESENTATION_ITEM('rotational speed',NUMERIC_MEASURE(-3000.),#20)")
    new("ACTION_PROPERTY_REPRESENTATION('','',%s,%s)" % (new("ACTION_PROPERTY('spindle','',%s)" % tech), spindle))
    new("ACTION_PROPERTY_REPRESENTATION('','',%s,#48)" % new("ACTION_PROPERTY('feedrate reference','',%s)" % tech))
    functions = new("MACHINING_FUNCTIONS('functions','milling','','')")
    coolant = new("REPRESENTATION('',(#%d),#24)" % (n[0] + 2))
    new("DESCRIPTIVE_REPRESENTATION_ITEM('coolant','coolant on')")
    new("ACTION_PROPERTY_REPRESENTATION('','',%s,%s)" % (new("ACTION_PROPERTY('coolant','',%s)" % functions), coolant))
    operations = []
    for s in range(args.steps):
        ws = new("MACHINING_WORKINGSTEP('step %d','machining','','')" % (s + 1))
        new("MACHINING_PROCESS_SEQUENCE_RELATIONSHIP('','',#32,%s,%d.)" % (ws, s + 1))
        new("ACTION_PROPERTY_REPRESENTATION('','',%s,#56)" % new("ACTION_PROPERTY('security plane','',%s)" % ws))
        op = new("BOTTOM_AND_SIDE_MILLING_OPERATION('step %d','finishing','','')" % (s + 1))
        operations.append(op)
        new("MACHINING_OPERATION_RELATIONSHIP('','',%s,%s)" % (ws, op))
        process = new("MACHINING_FEATURE_PROCESS('step %d toolpaths','','','')" % (s + 1))
        new("MACHINING_FEATURE_RELATIONSHIP('','',%s,%s)" % (ws, process))
        feature = new("INSTANCED_FEATURE('step %d toolpaths','toolpath','step %d toolpaths','toolpath',#38,.T.)"
                      % (s + 1, s + 1))
        new("PROCESS_PROPERTY_ASSOCIATION('','',%s,%s)" % (new("PROPERTY_PROCESS('machining','',%s,'')" % process),
                                                         feature))
        new("MACHINING_TECHNOLOGY_RELATIONSHIP('','',%s,%s)" % (op, tech))
        new("MACHINING_FUNCTIONS_RELATIONSHIP('','',%s,%s)" % (op, functions))
        y0 = (s % 10) * 8.0
        for p in range(args.paths):
            tp = new("MACHINING_TOOLPATH('path %d','cutter location trajectory','','')" % (p + 1))
            new("MACHINING_TOOLPATH_SEQUENCE_RELATIONSHIP('','',%s,%s,%d.)" % (op, tp, p + 1))
            for prop, rep in (("priority", "#40"), ("trajectory type", "#42"), ("direction", "#44")):
                new("ACTION_PROPERTY_REPRESENTATION('','',%s,%s)" % (new("ACTION_PROPERTY('%s','',%s)" % (prop, tp)),
                                                                     rep))
            y = y0 + p * 0.3
            points = [new("CARTESIAN_POINT('',(%.4f,%.4f,-3.))" % (10 + 80.0 * k / (args.points - 1),
                                                                y + (0.2 if k % 2 else 0.0)))
                      for k in range(args.points)]
            curve = new("POLYLINE('',(%s))" % ",".join(points))
            rep = new("REPRESENTATION('',(%s),#23)" % curve)
            new("ACTION_PROPERTY_REPRESENTATION('','',%s,%s)" % (new("ACTION_PROPERTY('basic curve','',%s)" % tp), rep))
    tool = new("MACHINING_TOOL('T1','endmill',(%s),#%d)" % (",".join(operations), n[0] + 2))
    new("ACTION_RESOURCE_TYPE('milling cutting tool')")
    body = new("MACHINING_TOOL_BODY_REPRESENTATION('endmill',(#%d),#24)" % (n[0] + 2))
    new("MEASURE_REPRESENTATION_ITEM('number of teeth',COUNT_MEASURE(4.),#13)")
    new("RESOURCE_PROPERTY_REPRESENTATION('','',%s,%s)" % (new("RESOURCE_PROPERTY('tool body','',%s)" % tool), body))
    dims = new("MACHINING_TOOL_DIMENSION_REPRESENTATION('milling',(#%d),#24)" % (n[0] + 2))
    new("(LENGTH_MEASURE_WITH_UNIT()MEASURE_REPRESENTATION_ITEM()MEASURE_WITH_UNIT(LENGTH_MEASURE(10.),#4)"
        "REPRESENTATION_ITEM('diameter'))")
    new("REPRESENTATION_RELATIONSHIP('','',%s,%s)" % (body, dims))
    out.append("ENDSEC;\nEND-ISO-10303-21;\n")
    with open(args.output, "w") as f:
        f.write("\n".join(out))
    print("gen-aim-toolpaths: wrote %s: %d instances, %d workingsteps, %d toolpaths, %d points"
          % (args.output, n[0], args.steps, args.steps * args.paths, args.steps * args.paths * args.points))


if __name__ == "__main__":
    main()
