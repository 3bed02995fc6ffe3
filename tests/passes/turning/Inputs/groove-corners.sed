# Rounds the corners of the shaft's 3 mm groove (lathe-shaft.stp) to 0.6 mm,
# more than its 2 mm grooving insert's 0.2 mm (groove-corners.test).
s/^#29=SQUARE_U_PROFILE(\$,#87,#88,90.,#88,90.);/#29=SQUARE_U_PROFILE($,#87,#300,90.,#300,90.);\n#300=TOLERANCED_LENGTH_MEASURE(0.6,#77);/
