F=0.07; D=0.06
def boxes_obj(name, desc, boxes):
    out=[f"# {name}: {desc}",
         "# Emilion facade element (CC0). Units: x and y span the opening's width and height",
         "# (0..1, y up from its bottom edge); z in metres, 0 at the opening's back (the glass),",
         "# positive towards the street. Each box is a closed solid of its own.",
         f"o {name}"]
    faces=[]
    for k,(x0,y0,x1,y1,z0,z1) in enumerate(boxes):
        vs=[(x0,y0,z0),(x1,y0,z0),(x1,y1,z0),(x0,y1,z0),(x0,y0,z1),(x1,y0,z1),(x1,y1,z1),(x0,y1,z1)]
        for v in vs: out.append("v %g %g %g"%v)
        b=8*k
        for q in [(5,6,7,8),(1,4,3,2),(1,2,6,5),(4,8,7,3),(1,5,8,4),(2,3,7,6)]:
            faces.append("f "+" ".join(str(b+i) for i in q))
    return "\n".join(out+faces)+"\n"
ring=[(0,0,1,F,0,D),(0,1-F,1,1,0,D),(0,F,F,1-F,0,D),(1-F,F,1,1-F,0,D)]
h=F/2
mull=[(0.5-h,F,0.5+h,1-F,0,D)]
t=0.65
cross=mull+[(F,t-h,0.5-h,t+h,0,D),(0.5+h,t-h,1-F,t+h,0,D)]
sash=[(F,0.5-h,1-F,0.5+h,0,D)]
door=[(0,0,F,1-F,0,D),(1-F,0,1,1-F,0,D),(0,1-F,1,1,0,D),(0.2,0.1,0.8,0.45,0,0.03),(0.2,0.55,0.8,0.85,0,0.03)]
els={
 'window_plain':("a window frame round one pane",ring),
 'window_mullion':("a window frame with a vertical mullion (two casements)",ring+mull),
 'window_cross':("a window frame with a mullion and a transom at 0.65 of its height (French cross window)",ring+cross),
 'window_sash':("a window frame with a horizontal meeting rail at half height (sash window)",ring+sash),
 'door_panel':("a door frame (sides and head) with two raised panels",door),
 # wall mouldings: a leaf of wall that tile refinement found round a window (its casing) or
 # below it (its sill) carries one of these, standing out of the wall's front
 'wall_frame':("a strip of window casing standing 3 cm out of the wall",[(0,0,1,1,0,0.03)]),
 'wall_sill':("a window sill standing 6 cm out of the wall",[(0,0,1,1,0,0.06)]),
}
for n,(d,b) in els.items():
    open(n+".obj","w").write(boxes_obj(n,d,b))
