"""Writers (and readers) of design files, one format per file: design JSON, SVG drawing."""
