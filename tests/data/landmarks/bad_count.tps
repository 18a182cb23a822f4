LM=-2
