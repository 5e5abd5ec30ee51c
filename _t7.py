from reference import simulate, ReferenceOptions
from reference.scenes import as_scene
sc = as_scene('triangle-chatter').with_impact_law('moreau')
o = ReferenceOptions(impact_law='moreau')
for i in range(1500):
    simulate(sc, options=o)
