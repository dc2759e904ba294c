"""Heat conduction, thermoelasticity, beam theory and reduced models."""
