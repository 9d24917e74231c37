// placeholder so the library has a source; replaced as the folder grows
