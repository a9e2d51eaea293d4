"""The observables layer: what is read off a state or a run - step rows, drilling quantities (96)-(99)
as pure functions, the von Mises stress (100), spectra (Section 6.8)."""
