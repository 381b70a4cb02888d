// Fixture for the layer check: the core including ITK (must be refused).
#include <itkImage.h>
