"""Floor maps: random generation (OpenCV shapes), the five named maps, RGB rendering."""
