"""The physics of one mesh: geometry, ISO 6336, the sliced potential-energy stiffness, its
Fourier series, the backlash models."""
