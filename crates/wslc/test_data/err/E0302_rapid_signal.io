doGrip do dogrip 0
diPartReady di dopartready 0
