"""Static scene reflectors for mdframework (effect kind ``static_scene``)."""
