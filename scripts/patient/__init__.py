"""Patient-specific pipeline (paper §2.4, §4.2): from a lumen centerline CSV to a placed balloon and
stent and a three-layer tet10 artery mesh. Entry point: prepare.prepare_scene (used by the
launcher for scenes with a `patient:` section). Units: mm."""
