#include <petscsnes.h>
#include <petscviewer.h>
